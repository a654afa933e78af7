# Blender releases the project is tested on (sourced by setup.sh and test.sh).
# Each has requirements/bpy-<version>.txt whose first line names its Python ("... on Python 3.11").

HAO_DEFAULT_BPY=5.3.0          # development and the sample job: .venv
HAO_CI_BPY="4.2.23 5.3.0"      # the oldest and the newest supported release: what CI tests

requirements_for() {
  local req="requirements/bpy-$1.txt"
  if [ ! -f "$req" ]; then
    echo "no $req: known releases are $(ls requirements | sed -n 's/^bpy-\(.*\)\.txt$/\1/p' | tr '\n' ' ')" >&2
    exit 2
  fi
  echo "$req"
}

venv_for() {
  if [ "$1" = "$HAO_DEFAULT_BPY" ]; then echo ".venv"; else echo ".venv-$1"; fi
}

python_version_for() {
  sed -n '1s/.*on Python \([0-9]*\.[0-9]*\).*/\1/p' "$(requirements_for "$1")"
}

# A runnable interpreter of that version: on PATH, else from pyenv's versions folder.
find_python() {
  local want="$1" candidate
  for candidate in "python$want" "$(pyenv root 2>/dev/null)"/versions/"$want".*/bin/python"$want" \
                   "$HOME/.pyenv/versions/$want".*/bin/python"$want" /usr/bin/python"$want"; do
    if command -v "$candidate" >/dev/null 2>&1 && "$candidate" -c "" >/dev/null 2>&1; then
      command -v "$candidate"
      return
    fi
  done
  echo "Python $want is needed for this Blender release; install it (for example 'pyenv install $want')" >&2
  exit 2
}
