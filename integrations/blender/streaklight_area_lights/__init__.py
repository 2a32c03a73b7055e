"""EXT_lights_area for Blender's glTF importer and exporter.

Import: every node with an ``EXT_lights_area`` rectangle light gets a Blender area light
(shape RECTANGLE) as a child: width ``size * rect.aspect`` along the node's X, height ``size``
along its Y, emitting along its -Z, colour ``color``, power ``pi * width * height *
intensity`` watts: the flux of a Lambertian rectangle of radiance L and area A is P = pi A L,
and a Blender area light's power is the flux it emits, so the light's radiance in a render is
``color * intensity``, the radiance streaklight fitted (an emissive surface of strength
``intensity`` has that radiance too). streaklight's emissive fallback quads are hidden from rendering when their light was
imported (they stay visible in the viewport).

Export: every rectangle (or square) area light is written back as an ``EXT_lights_area``
light on its node, by the inverse conversion.
"""

import math

import bpy
from io_scene_gltf2.io.com.gltf2_io_extensions import Extension

bl_info = {
    "name": "streaklight EXT_lights_area",
    "description": "Import and export glTF EXT_lights_area rectangle area lights",
    "author": "streaklight",
    "version": (0, 1, 0),
    "blender": (4, 2, 0),
    "location": "File > Import/Export > glTF 2.0",
    "category": "Import-Export",
}

EXTENSION = "EXT_lights_area"

# glTF is +Y up, Blender +Z up; the importer turns a glTF node's local frame so that its local
# Y becomes Blender's local Z. A Blender light emits along its local -Z, so its object turns
# +90 degrees about X relative to the node's object (the importer's own correction for
# KHR_lights_punctual lights; the exporter undoes it for every light).
_CORRECTION = (math.sqrt(0.5), math.sqrt(0.5), 0.0, 0.0)


def _extension(data):
    """`data.extensions` or `{}`, whatever the importer's objects hold."""
    ext = getattr(data, "extensions", None)
    return ext if isinstance(ext, dict) else {}


def power_from_intensity(width, height, intensity):
    """Blender watts of a rectangle light of radiance `intensity`: P = pi A L."""
    return math.pi * width * height * intensity


def intensity_from_power(width, height, power):
    """The radiance of a Blender area light of `power` watts: L = P / (pi A)."""
    return power / (math.pi * width * height)


class glTF2ImportUserExtension:
    """The importer calls each hook with its own arguments, then the importer state `gltf`."""

    def __init__(self):
        self.light_parents = set()
        self.quads = []

    def gather_import_node_after_hook(self, vnode, gltf_node, obj, gltf):
        extras = getattr(gltf_node, "extras", None) or {}
        if isinstance(extras, dict) and (extras.get("streaklight") or {}).get("role") == "fallback-quad":
            self.quads.append(obj)
        node_ext = _extension(gltf_node).get(EXTENSION)
        if not node_ext or obj is None:
            return
        lights = _extension(gltf.data).get(EXTENSION, {}).get("lights", [])
        index = node_ext.get("light")
        if not isinstance(index, int) or not 0 <= index < len(lights):
            return
        light = lights[index]
        if light.get("type", "rect") != "rect":
            return
        height = float(light.get("size", 1.0))
        width = height * float(light.get("rect", {}).get("aspect", 1.0))
        data = bpy.data.lights.new(light.get("name") or obj.name, "AREA")
        data.shape = "RECTANGLE"
        data.size = width
        data.size_y = height
        data.color = [float(c) for c in light.get("color", [1.0, 1.0, 1.0])]
        data.energy = power_from_intensity(width, height, float(light.get("intensity", 1.0)))
        # The light object carries the glTF light's other fields for export.
        light_obj = bpy.data.objects.new(data.name, data)
        for collection in obj.users_collection:
            collection.objects.link(light_obj)
        light_obj.parent = obj
        light_obj.rotation_mode = "QUATERNION"
        light_obj.rotation_quaternion = _CORRECTION
        light_obj["gltf_light_name"] = light.get("name", "")
        self.light_parents.add(obj.name)

    def gather_import_scene_after_nodes_hook(self, gltf_scene, scene, gltf):
        for quad in self.quads:
            if quad.parent is not None and quad.parent.name in self.light_parents:
                quad.hide_render = True


class glTF2ExportUserExtension:
    """Collects the lights node by node, then lists them at the document's top level."""

    def __init__(self):
        self.lights = []

    def gather_node_hook(self, gltf2_object, blender_object, export_settings):
        if blender_object is None or blender_object.type != "LIGHT":
            return
        data = blender_object.data
        if data.type != "AREA" or data.shape not in ("RECTANGLE", "SQUARE"):
            return
        width = data.size
        height = data.size_y if data.shape == "RECTANGLE" else data.size
        name = blender_object.get("gltf_light_name") or data.name
        light = {
            "type": "rect",
            "color": list(data.color),
            "intensity": intensity_from_power(width, height, data.energy),
            "size": height,
            "rect": {"aspect": width / height},
            "name": name,
        }
        if gltf2_object.extensions is None:
            gltf2_object.extensions = {}
        self.lights.append(light)
        gltf2_object.extensions[EXTENSION] = Extension(
            name=EXTENSION, extension={"light": len(self.lights) - 1}, required=False
        )

    def gather_gltf_extensions_hook(self, gltf2_plan, export_settings):
        if not self.lights:
            return
        if gltf2_plan.extensions is None:
            gltf2_plan.extensions = {}
        gltf2_plan.extensions[EXTENSION] = Extension(
            name=EXTENSION, extension={"lights": self.lights}, required=False
        )


def register():
    pass


def unregister():
    pass
