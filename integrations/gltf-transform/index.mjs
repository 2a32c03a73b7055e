// EXT_lights_area for glTF-Transform: rectangle area lights on nodes, as streaklight writes
// them (a top-level `extensions.EXT_lights_area.lights` array and `{"light": i}` on nodes).
//
// glTF-Transform keeps an extension only through a registered Extension class; without one,
// `copy`, `dedup`, `prune`, `optimize` and every script drop the lights. With this one they
// come out as they went in: every field of every light object, in streaklight's key order,
// fields this class does not know included (kept verbatim), and each node's light.

import { Extension, ExtensionProperty, PropertyType } from '@gltf-transform/core';

export const EXT_LIGHTS_AREA = 'EXT_lights_area';

/** The fields that have getters; any other field of a light object is kept as it was. */
const KNOWN = new Set(['type', 'color', 'intensity', 'size', 'rect', 'name', 'extras', 'extensions']);

/**
 * A rectangle area light: centred on its node, `size` (its height) along the node's +Y, width
 * `size * aspect` along +X, emitting towards the node's -Z. Radiance = color * intensity.
 */
export class AreaLight extends ExtensionProperty {
  static EXTENSION_NAME = EXT_LIGHTS_AREA;

  init() {
    this.extensionName = EXT_LIGHTS_AREA;
    this.propertyType = 'AreaLight';
    this.parentTypes = [PropertyType.NODE];
  }

  getDefaults() {
    return Object.assign(super.getDefaults(), {
      lightType: 'rect',
      color: [1, 1, 1],
      intensity: 1,
      size: 1,
      aspect: 1,
      rectExtra: {},
      otherFields: {},
    });
  }

  /** "rect" (the only type streaklight writes). */
  getType() { return this.get('lightType'); }
  setType(type) { return this.set('lightType', type); }
  /** Linear RGB, components in [0, 1]. */
  getColor() { return this.get('color'); }
  setColor(color) { return this.set('color', color); }
  /** Radiance scale (nits for a calibrated photo). */
  getIntensity() { return this.get('intensity'); }
  setIntensity(intensity) { return this.set('intensity', intensity); }
  /** Height of the rectangle (along the node's +Y), scene units. */
  getSize() { return this.get('size'); }
  setSize(size) { return this.set('size', size); }
  /** Width / height. */
  getAspect() { return this.get('aspect'); }
  setAspect(aspect) { return this.set('aspect', aspect); }
  /** Width of the rectangle (along the node's +X). */
  getWidth() { return this.getSize() * this.getAspect(); }
}

/** The Extension: register it on a NodeIO (`io.registerExtensions([EXTLightsArea])`). */
export class EXTLightsArea extends Extension {
  static EXTENSION_NAME = EXT_LIGHTS_AREA;
  extensionName = EXT_LIGHTS_AREA;

  /** Creates a light, to attach with `node.setExtension('EXT_lights_area', light)`. */
  createLight(name = '') {
    return new AreaLight(this.document.getGraph(), name);
  }

  /** @hidden */
  read(context) {
    const json = context.jsonDoc.json;
    const defs = json.extensions?.[EXT_LIGHTS_AREA]?.lights ?? [];
    const lights = defs.map((def) => {
      const light = this.createLight(def.name ?? '');
      if (def.type !== undefined) light.setType(def.type);
      if (def.color !== undefined) light.setColor(def.color);
      if (def.intensity !== undefined) light.setIntensity(def.intensity);
      if (def.size !== undefined) light.setSize(def.size);
      const { aspect, ...rectExtra } = def.rect ?? {};
      if (aspect !== undefined) light.setAspect(aspect);
      light.set('rectExtra', rectExtra);
      light.set('hasRect', def.rect !== undefined);
      light.set('hasName', def.name !== undefined);
      const other = {};
      for (const [key, value] of Object.entries(def)) if (!KNOWN.has(key)) other[key] = value;
      if (def.extensions !== undefined) other.extensions = def.extensions;
      light.set('otherFields', other);
      light.set('fieldOrder', Object.keys(def));
      if (def.extras !== undefined) light.setExtras(def.extras);
      return light;
    });
    (json.nodes ?? []).forEach((nodeDef, i) => {
      const ext = nodeDef.extensions?.[EXT_LIGHTS_AREA];
      if (ext && lights[ext.light]) context.nodes[i].setExtension(EXT_LIGHTS_AREA, lights[ext.light]);
    });
    return this;
  }

  /** @hidden */
  write(context) {
    const json = context.jsonDoc.json;
    if (this.properties.size === 0) return this;
    const defs = [];
    const index = new Map();
    for (const light of this.properties) {
      const fields = {
        type: light.getType(),
        color: light.getColor(),
        intensity: light.getIntensity(),
        size: light.getSize(),
        rect: { aspect: light.getAspect(), ...light.get('rectExtra') },
        name: light.getName(),
        ...light.get('otherFields'),
      };
      if (Object.keys(light.getExtras()).length > 0) fields.extras = light.getExtras();
      // streaklight's key order, or the order the light was read in.
      const order = light.get('fieldOrder') ?? ['type', 'color', 'intensity', 'size', 'rect', 'name'];
      const def = {};
      for (const key of [...order, ...Object.keys(fields)]) {
        if (key in fields && !(key in def)) def[key] = fields[key];
      }
      if (light.get('hasName') === false && def.name === '') delete def.name;
      defs.push(def);
      index.set(light, defs.length - 1);
    }
    for (const node of this.document.getRoot().listNodes()) {
      const light = node.getExtension(EXT_LIGHTS_AREA);
      if (!light) continue;
      const nodeDef = json.nodes[context.nodeIndexMap.get(node)];
      nodeDef.extensions = nodeDef.extensions ?? {};
      nodeDef.extensions[EXT_LIGHTS_AREA] = { light: index.get(light) };
    }
    json.extensions = json.extensions ?? {};
    json.extensions[EXT_LIGHTS_AREA] = { lights: defs };
    return this;
  }
}
