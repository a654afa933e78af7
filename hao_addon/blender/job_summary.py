# SPDX-License-Identifier: GPL-3.0-or-later
"""What a bake job reports of each object it baked (BakeJob.summary, the --json report)."""
from __future__ import annotations


def job_summary(job) -> list[dict]:
    """One entry per baked object of the last bake (the --json report's objects): its
    triangles, UV map (and whether the job made it), covered texels, the method, the texel
    sets it baked with (core/bake/interleave.py: 1 where the method bakes one), shaded
    corners, the mesh instances that occluded it (blender/instances.py), and where they apply
    missed texels (Selected to Active), UDIM tiles, the texture set it joined; its estimated error (core/bake/error_estimate.py: rmse, p99,
    directions, capped; None with a single direction); with Re-bake Changed, what it re-baked
    (rebake.RebakeReport.as_dict: full and why, texels re-baked of those covered, the bound on
    the kept ones)."""
    out = []
    for obj, uv_name, result in job.results:
        st = job.own_stats.get(obj.name, result.stats)
        out.append(dict(name=obj.name, triangles=st["target_faces"], uv_map=uv_name,
                        uv_map_created=any(n == uv_name for _m, n in job.created_uv),
                        covered_texels=st["covered_texels"], method=st["method"],
                        texel_sets=st.get("texel_sets", 1),
                        smooth_corners=st["smooth_corners"], instanced_occluders=st.get("instanced_occluders", 0),
                        **({"texture_set": True} if job.request.options.texture_set else {}),
                        **({"missed_texels": st["missed_texels"]} if "missed_texels" in st else {}),
                        **({"udim_tiles": list(result.tiles)} if result.tiles else {}),
                        error=st.get("error"), **({"verify": st["verify"]} if "verify" in st else {}),
                        **({"rebake": st["rebake"]} if "rebake" in st else {})))
    return out
