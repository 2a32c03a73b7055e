#!/usr/bin/env python3
"""Render a streaklight glTF scene once with Mitsuba 3 (LLVM backend) and time it.

The speed benchmark (benches/speed.rs) runs this in a fresh process per measurement: it is
what a user would otherwise run to see the same scene. The script reads the glTF itself
(json and numpy, buffers from .bin files or data: URIs): the water mesh (the mesh nodes whose
node or mesh name contains "water", as streaklight picks it) with its world transform, the
first camera, and the EXT_lights_area "rect" lights. As in streaklight's model of a night
scene only the water reflects: the other meshes (the wall) are left out unless
--other-meshes is given, which adds them as diffuse surfaces of their base colour. The water
becomes a rough dielectric of its KHR_materials_ior with a Beckmann alpha of roughness^2
(alpha^2 = 2 / (e + 2) for gloss e, docs/method.md), each light a one-sided rectangle
emitter of radiance colour x intensity facing the light node's local -Z. The sensor is a
perspective camera of the glTF camera's vertical field of view, an independent sampler and
a path integrator of the given maximum depth.

It prints one JSON object: the Mitsuba version and variant, the seconds of the import
(import mitsuba + set_variant), of reading the glTF, of building the scene (meshes and
load_dict, with the BVH) and of the render (mi.render and a sync), and the triangle count.

Usage: mitsuba_render.py SCENE.gltf [--width W] [--height H] [--spp N] [--max-depth D]
                         [--variant V] [--other-meshes] [--out IMAGE.exr]
"""

import argparse
import base64
import json
import math
import os
import sys
import time

T_START = time.perf_counter()

import numpy as np  # noqa: E402

COMPONENTS = {5120: np.int8, 5121: np.uint8, 5122: np.int16, 5123: np.uint16,
              5125: np.uint32, 5126: np.float32}
WIDTHS = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}


def fail(message):
    print(message, file=sys.stderr)
    sys.exit(1)


def load_buffers(doc, base):
    out = []
    for i, buf in enumerate(doc.get("buffers", [])):
        uri = buf.get("uri")
        if uri is None:
            fail(f"{base}: buffer {i} has no uri (a .glb is not read by this script)")
        if uri.startswith("data:"):
            out.append(base64.b64decode(uri.split(",", 1)[1]))
        else:
            with open(os.path.join(os.path.dirname(base), uri), "rb") as f:
                out.append(f.read())
    return out


def accessor(doc, buffers, index):
    acc = doc["accessors"][index]
    view = doc["bufferViews"][acc["bufferView"]]
    dtype = np.dtype(COMPONENTS[acc["componentType"]])
    width = WIDTHS[acc["type"]]
    count = acc["count"]
    start = view.get("byteOffset", 0) + acc.get("byteOffset", 0)
    stride = view.get("byteStride", dtype.itemsize * width)
    data = buffers[view["buffer"]]
    if stride == dtype.itemsize * width:
        arr = np.frombuffer(data, dtype=dtype, count=count * width, offset=start)
        return arr.reshape(count, width) if width > 1 else arr
    rows = np.ndarray((count, width), dtype=dtype, buffer=data, offset=start,
                      strides=(stride, dtype.itemsize))
    return np.array(rows)


def node_matrix(node):
    if "matrix" in node:
        return np.array(node["matrix"], dtype=np.float64).reshape(4, 4).T
    t = np.array(node.get("translation", [0.0, 0.0, 0.0]))
    x, y, z, w = node.get("rotation", [0.0, 0.0, 0.0, 1.0])
    s = np.array(node.get("scale", [1.0, 1.0, 1.0]))
    r = np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])
    m = np.eye(4)
    m[:3, :3] = r * s
    m[:3, 3] = t
    return m


def instances(doc):
    """(node, world matrix) of every node under the default scene."""
    scene = doc.get("scenes", [{}])[doc.get("scene", 0)]
    stack = [(n, np.eye(4)) for n in scene.get("nodes", [])]
    while stack:
        index, parent = stack.pop()
        node = doc["nodes"][index]
        world = parent @ node_matrix(node)
        yield node, world
        stack.extend((c, world) for c in node.get("children", []))


def is_water(doc, node):
    names = [node.get("name", ""), doc["meshes"][node["mesh"]].get("name", "")]
    return any("water" in n.lower() for n in names)


def read_gltf(path, other_meshes=False):
    """The scene's water (and other meshes if asked), camera and rect lights, in world
    space."""
    with open(path, encoding="utf-8") as f:
        doc = json.load(f)
    buffers = load_buffers(doc, path)
    materials = doc.get("materials", [])
    lights = doc.get("extensions", {}).get("EXT_lights_area", {}).get("lights", [])
    meshes, rects, camera = [], [], None
    for node, world in instances(doc):
        if "mesh" in node and (other_meshes or is_water(doc, node)):
            normal_matrix = np.linalg.inv(world[:3, :3]).T
            for prim in doc["meshes"][node["mesh"]]["primitives"]:
                if prim.get("mode", 4) != 4:
                    continue
                pos = accessor(doc, buffers, prim["attributes"]["POSITION"]).astype(np.float64)
                pos = pos @ world[:3, :3].T + world[:3, 3]
                normals = None
                if "NORMAL" in prim["attributes"]:
                    n = accessor(doc, buffers, prim["attributes"]["NORMAL"]) @ normal_matrix.T
                    normals = n / np.linalg.norm(n, axis=1, keepdims=True)
                if "indices" in prim:
                    faces = accessor(doc, buffers, prim["indices"]).astype(np.uint32)
                else:
                    faces = np.arange(len(pos), dtype=np.uint32)
                material = materials[prim["material"]] if "material" in prim else {}
                meshes.append((pos, normals, faces.reshape(-1, 3), material))
        if "camera" in node and camera is None:
            persp = doc["cameras"][node["camera"]].get("perspective")
            if persp is not None:
                camera = (persp, world)
        ext = node.get("extensions", {}).get("EXT_lights_area")
        if ext is not None and ext.get("light", -1) < len(lights):
            light = lights[ext["light"]]
            if light.get("type", "rect") == "rect":
                rects.append((light, world))
    if camera is None:
        fail(f"{path}: no perspective camera")
    if not meshes:
        fail(f"{path}: no mesh node named like \"water\"")
    return meshes, camera, rects


def bsdf_of(material):
    pbr = material.get("pbrMetallicRoughness", {})
    ior = material.get("extensions", {}).get("KHR_materials_ior")
    if ior is not None:
        alpha = pbr.get("roughnessFactor", 1.0) ** 2
        return {"type": "roughdielectric", "distribution": "beckmann", "alpha": alpha,
                "int_ior": ior.get("ior", 1.5), "ext_ior": 1.0}
    colour = pbr.get("baseColorFactor", [1.0, 1.0, 1.0, 1.0])[:3]
    return {"type": "diffuse", "reflectance": {"type": "rgb", "value": colour}}


def scene_dict(mi, meshes, camera, rects, args):
    out = {"type": "scene",
           "integrator": {"type": "path", "max_depth": args.max_depth}}
    persp, cam_world = camera
    # Mitsuba's camera looks along local +Z with +X to the left; glTF's along -Z, +X right.
    flip = np.diag([-1.0, 1.0, -1.0, 1.0])
    out["sensor"] = {
        "type": "perspective",
        "fov_axis": "y",
        "fov": math.degrees(persp["yfov"]),
        "near_clip": persp.get("znear", 0.01),
        "far_clip": persp.get("zfar", 1e4),
        "to_world": mi.ScalarTransform4f((cam_world @ flip).tolist()),
        "film": {"type": "hdrfilm", "width": args.width, "height": args.height,
                 "rfilter": {"type": "box"}},
        "sampler": {"type": "independent", "sample_count": args.spp},
    }
    for i, (pos, normals, faces, material) in enumerate(meshes):
        props = mi.Properties()
        props["bsdf"] = mi.load_dict(bsdf_of(material))
        mesh = mi.Mesh(f"mesh{i}", len(pos), len(faces), props=props,
                       has_vertex_normals=normals is not None)
        params = mi.traverse(mesh)
        params["vertex_positions"] = mi.Float(pos.astype(np.float32).ravel())
        params["faces"] = mi.UInt(faces.ravel())
        if normals is not None:
            params["vertex_normals"] = mi.Float(normals.astype(np.float32).ravel())
        params.update()
        out[f"mesh{i}"] = mesh
    for i, (light, world) in enumerate(rects):
        height = light.get("size", 1.0)
        width = height * light.get("rect", {}).get("aspect", 1.0)
        # Mitsuba's rectangle spans [-1, 1]^2 and emits towards local +Z; the light's
        # emits towards its node's -Z, so turn it half a turn about Y (it is symmetric in X).
        local = np.diag([-width / 2, height / 2, -1.0, 1.0])
        radiance = [c * light.get("intensity", 1000.0) for c in light.get("color", [1, 1, 1])]
        out[f"light{i}"] = {
            "type": "rectangle",
            "to_world": mi.ScalarTransform4f((world @ local).tolist()),
            "emitter": {"type": "area", "radiance": {"type": "rgb", "value": radiance}},
        }
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("scene")
    parser.add_argument("--width", type=int, default=600)
    parser.add_argument("--height", type=int, default=600)
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--max-depth", type=int, default=3)
    parser.add_argument("--variant", default="llvm_ad_rgb")
    parser.add_argument("--other-meshes", action="store_true",
                        help="also render the meshes that are not the water, as diffuse")
    parser.add_argument("--out", help="also write the image (EXR)")
    args = parser.parse_args()

    t = time.perf_counter()
    import drjit as dr
    import mitsuba as mi
    mi.set_variant(args.variant)
    t_import = time.perf_counter() - t

    t = time.perf_counter()
    meshes, camera, rects = read_gltf(args.scene, args.other_meshes)
    t_read = time.perf_counter() - t

    t = time.perf_counter()
    scene = mi.load_dict(scene_dict(mi, meshes, camera, rects, args))
    dr.sync_thread()
    t_load = time.perf_counter() - t

    t = time.perf_counter()
    image = mi.render(scene, spp=args.spp, seed=1)
    dr.eval(image)
    dr.sync_thread()
    t_render = time.perf_counter() - t

    if args.out:
        mi.util.write_bitmap(args.out, image)
    print(json.dumps({
        "mitsuba": mi.__version__,
        "drjit": dr.__version__,
        "variant": mi.variant(),
        "threads": dr.thread_count() if hasattr(dr, "thread_count") else None,
        "triangles": int(sum(len(f) for _, _, f, _ in meshes)),
        "lights": len(rects),
        "width": args.width,
        "height": args.height,
        "spp": args.spp,
        "max_depth": args.max_depth,
        "import_s": t_import,
        "read_s": t_read,
        "load_s": t_load,
        "render_s": t_render,
    }))


if __name__ == "__main__":
    main()
