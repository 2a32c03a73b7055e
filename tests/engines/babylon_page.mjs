// Browser side of babylon_check.mjs: loads a glTF with Babylon's own glTF loader (which imports
// EXT_lights_area), renders it from the file's camera, and hands the created lights back as
// plain numbers. All comparisons happen in Node, so this file only measures.

import { Engine } from "@babylonjs/core/Engines/engine.js";
import { Scene } from "@babylonjs/core/scene.js";
import { Color3, Color4 } from "@babylonjs/core/Maths/math.color.js";
import { Vector3 } from "@babylonjs/core/Maths/math.vector.js";
import { Tools } from "@babylonjs/core/Misc/tools.js";
import { AppendSceneAsync } from "@babylonjs/core/Loading/sceneLoader.js";
import { SceneLoaderFlags } from "@babylonjs/core/Loading/sceneLoaderFlags.js";
import { StandardMaterial } from "@babylonjs/core/Materials/standardMaterial.js";
import { RectAreaLight } from "@babylonjs/core/Lights/rectAreaLight.js";
import "@babylonjs/loaders/glTF/index.js";

// Babylon fetches its area-light LTC tables from its CDN; the harness serves the same tables
// under /babylon-assets/ (see babylon_check.mjs).
Tools.AssetBaseUrl = `${location.origin}/babylon-assets`;
// No loading screen: it is a UI side-effect module we do not need.
SceneLoaderFlags.ShowLoadingScreen = false;

const canvas = document.getElementById("view");
const engine = new Engine(canvas, false, { preserveDrawingBuffer: true, stencil: true });
let scene;

const withTimeout = (promise, seconds, what) => Promise.race([
  promise,
  new Promise((_, reject) => setTimeout(() => reject(new Error(`${what} within ${seconds} s`)), seconds * 1000)),
]);
const arr3 = (v) => [v.x, v.y, v.z];
const waitFrames = (n) => new Promise((resolve) => {
  let left = n;
  const tick = () => (--left <= 0 ? resolve() : requestAnimationFrame(tick));
  requestAnimationFrame(tick);
});

/** Loads `url` into a new scene; returns what Babylon created. */
window.loadScene = async (url, options = {}) => {
  scene?.dispose(); // one page serves several scenes: loading Babylon's modules takes seconds
  scene = new Scene(engine);
  scene.useRightHandedSystem = !!options.rightHanded;
  scene.clearColor = new Color4(0, 0, 0, 1); // background black: brightness must come from lights
  console.log(`loading ${url}`);
  await AppendSceneAsync(url, scene);
  console.log("loaded; waiting for the scene to be ready");
  const camera = scene.cameras[0];
  if (!camera) throw new Error("the glTF made no camera");
  scene.activeCamera = camera;
  await withTimeout(scene.whenReadyAsync(), 60, "the scene never became ready");
  // The LTC tables arrive asynchronously; a light is ready once they are uploaded.
  for (let i = 0; i < 200 && !scene.lights.every((l) => l._isReady()); i++) await waitFrames(1);
  console.log("ready; rendering");
  // Frames are rendered on demand, not in a loop: software WebGL takes a second or more per
  // frame of this scene, and a busy loop would only slow the screenshots down.
  scene.render();
  scene.render();

  const root = scene.getMeshByName("__root__");
  const lights = scene.lights.map((light) => {
    const isRect = light instanceof RectAreaLight;
    const parent = light.parent;
    parent?.computeWorldMatrix(true);
    const m = parent ? parent.getWorldMatrix() : null;
    // What Babylon's shader uses (RectAreaLight._computeTransformedInformation): the position,
    // width vector (width, 0, 0) and height vector (0, height, 0) through the parent's world matrix.
    const pos = m ? Vector3.TransformCoordinates(light.position, m) : light.position;
    const w = new Vector3(isRect ? light.width : 0, 0, 0);
    const h = new Vector3(0, isRect ? light.height : 0, 0);
    return {
      name: light.name,
      className: light.getClassName(),
      enabled: light.isEnabled(),
      pointers: light._internalMetadata?.gltf?.pointers ?? [],
      position: arr3(pos),
      widthVector: arr3(m ? Vector3.TransformNormal(w, m) : w),
      heightVector: arr3(m ? Vector3.TransformNormal(h, m) : h),
      width: isRect ? light.width : null,
      height: isRect ? light.height : null,
      diffuse: [light.diffuse.r, light.diffuse.g, light.diffuse.b],
      intensity: light.intensity,
      falloffType: light.falloffType,
      ltcReady: light._isReady(),
    };
  });
  root.computeWorldMatrix(true);
  return {
    lights,
    rootWorldMatrix: Array.from(root.getWorldMatrix().m),
    meshes: scene.meshes.map((mesh) => mesh.name),
  };
};

/**
 * Renders only the mesh named `meshName` (and its sub-meshes), in flat white on black: the
 * water mask that the screenshot checks use.
 */
window.showOnly = async (meshName) => {
  const white = new StandardMaterial("mask", scene);
  white.disableLighting = true;
  white.emissiveColor = new Color3(1, 1, 1);
  white.backFaceCulling = false;
  const node = scene.getNodeByName(meshName);
  if (!node) throw new Error(`no node named ${meshName}`);
  const keep = new Set([node, ...node.getChildMeshes(false)]);
  let kept = 0;
  for (const mesh of scene.meshes) {
    if (keep.has(mesh) && mesh.getTotalVertices() > 0) {
      mesh.material = white;
      kept++;
    } else {
      mesh.isVisible = false;
    }
  }
  if (kept === 0) throw new Error(`node ${meshName} has no mesh`);
  await withTimeout(scene.whenReadyAsync(), 60, "the mask never became ready");
  scene.render();
};
