"""Checks the add-on in the real Blender (the `bpy` package): imports a streaklight fit output,
compares every area light with the fit's report, exports it as .glb, imports that again and
compares the lights once more.

usage: python3 check_roundtrip.py LIT.gltf REPORT.json WORK_DIR
Prints one line per check; exits 1 if any fails.
"""

import json
import math
import os
import sys

import bpy  # noqa: I001 (bpy first: it puts addon_utils and mathutils on the path)
import addon_utils
from mathutils import Vector

HERE = os.path.dirname(os.path.abspath(__file__))
ADDON = "streaklight_area_lights"

# Blender stores transforms, sizes and power as 32-bit floats: 1e-6 relative to the scene's
# scale (lights a few metres from the origin) is a few float32 steps.
TOL = 1e-6


def gltf_to_blender(v):
    """glTF +Y up to Blender +Z up: (x, y, z) -> (x, -z, y)."""
    return Vector((v[0], -v[2], v[1]))


def enable_addon():
    sys.path.insert(0, os.path.dirname(HERE))
    addon_utils.enable(ADDON, default_set=True, persistent=True)
    if ADDON not in bpy.context.preferences.addons:
        raise SystemExit(f"cannot enable the add-on {ADDON}")


def import_file(path):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    enable_addon()
    bpy.ops.import_scene.gltf(filepath=path)
    lights = {}
    for obj in bpy.data.objects:
        if obj.type == "LIGHT" and obj.data.type == "AREA":
            m = obj.matrix_world
            lights[obj.get("gltf_light_name") or obj.name] = {
                "position": m.translation.copy(),
                "emits": (m.to_3x3() @ Vector((0, 0, -1))).normalized(),
                "up": (m.to_3x3() @ Vector((0, 1, 0))).normalized(),
                "width": obj.data.size,
                "height": obj.data.size_y,
                "energy": obj.data.energy,
                "color": Vector(obj.data.color),
            }
    quads = [o for o in bpy.data.objects if "(streaklight fallback quad)" in o.name]
    return lights, quads


def close(a, b, tol):
    return abs(a - b) <= tol * max(1.0, abs(a), abs(b))


def main():
    lit, report_path, work = sys.argv[1:4]
    report = json.load(open(report_path))
    nits = report["settings"]["nits_scale"]
    failures = []

    def check(ok, what):
        print(("ok: " if ok else "FAILED: ") + what)
        if not ok:
            failures.append(what)

    lights, quads = import_file(lit)
    check(len(lights) == len(report["lights"]), f"{len(lights)} area lights imported, the report has {len(report['lights'])}")
    for want in report["lights"]:
        got = lights.get(want["name"])
        if got is None:
            check(False, f"{want['name']}: no area light imported")
            continue
        peak = max(want["radiance"])
        expect = {
            "position": gltf_to_blender(want["node_translation"]),
            "emits": gltf_to_blender(want["plane"]["normal"]).normalized(),
            "up": gltf_to_blender(want["v_axis"]).normalized(),
        }
        for key, v in expect.items():
            err = (got[key] - v).length
            check(err <= TOL * max(1.0, v.length), f"{want['name']} {key}: {tuple(got[key])} vs {tuple(v)} (off by {err:.2e})")
        check(close(got["width"], want["width"], TOL), f"{want['name']} width {got['width']} vs {want['width']}")
        check(close(got["height"], want["height"], TOL), f"{want['name']} height {got['height']} vs {want['height']}")
        power = math.pi * want["width"] * want["height"] * peak * nits
        check(close(got["energy"], power, TOL), f"{want['name']} power {got['energy']} W vs pi A L = {power}")
        color = Vector([c / peak for c in want["radiance"]])
        check((got["color"] - color).length <= TOL, f"{want['name']} colour {tuple(got['color'])} vs {tuple(color)}")
    check(len(quads) == len(report["lights"]) and all(q.hide_render for q in quads),
          f"{len(quads)} fallback quads, all hidden from render")

    out = os.path.join(work, "blender-roundtrip.glb")
    bpy.ops.export_scene.gltf(filepath=out, export_format="GLB", export_lights=True)
    again, _ = import_file(out)
    check(set(again) == set(lights), f"re-imported lights {sorted(again)} vs {sorted(lights)}")
    for name, first in lights.items():
        second = again.get(name)
        if second is None:
            continue
        worst = max(
            max((first[k] - second[k]).length for k in ("position", "emits", "up", "color")),
            *(abs(first[k] - second[k]) / max(1.0, abs(first[k])) for k in ("width", "height", "energy")),
        )
        check(worst <= TOL, f"{name}: export and re-import, largest difference {worst:.2e}")
    if failures:
        print(f"{len(failures)} check(s) failed")
        sys.exit(1)


main()
