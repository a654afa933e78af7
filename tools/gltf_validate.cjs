// SPDX-License-Identifier: GPL-3.0-or-later
// Validate .glb/.gltf files with the Khronos glTF Validator (installed by tools/setup.sh into
// .tools/gltf-validator): prints one JSON line per file {file, errors, warnings, messages}
// (messages: the errors' codes and pointers) and exits 1 if any file has an error.
//
//   node tools/gltf_validate.cjs FILE.glb [...]
'use strict';
const fs = require('fs');
const path = require('path');
const validator = require(path.join(__dirname, '..', '.tools', 'gltf-validator', 'package'));

async function main(files) {
  let failed = false;
  for (const file of files) {
    const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)));
    const issues = report.issues;
    const messages = issues.messages.filter((m) => m.severity === 0).map((m) => `${m.code} ${m.pointer || ''}`);
    console.log(JSON.stringify({ file, errors: issues.numErrors, warnings: issues.numWarnings, messages }));
    failed = failed || issues.numErrors > 0;
  }
  process.exit(failed ? 1 : 0);
}

main(process.argv.slice(2)).catch((error) => { console.error(String(error)); process.exit(2); });
