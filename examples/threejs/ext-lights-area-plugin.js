// A GLTFLoader plugin that imports EXT_lights_area rectangle lights as THREE.RectAreaLight.
//
//   import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
//   import { EXTLightsAreaPlugin } from './ext-lights-area-plugin.js';
//   const loader = new GLTFLoader().register( ( parser ) => new EXTLightsAreaPlugin( parser ) );
//
// The extension (multi-vendor draft, KhronosGroup/glTF pull request 2525) keeps its lights in
// the top-level `extensions.EXT_lights_area.lights`:
//   { type: "rect", color: [r, g, b] (linear), intensity (nits), size (height), rect: { aspect } }
// and a node places one with `extensions.EXT_lights_area.light = index`. The light is centred
// on the node, its width along local X, its height along local Y, and it emits towards local -Z.
//
// THREE.RectAreaLight uses the same frame: its shader (LTC_Evaluate) lights only the side of
// the rectangle its local -Z points to, so the light is attached to the node as it is, with no
// extra rotation. Its `intensity` is luminance in nits, like the extension's.
//
// RectAreaLight only works with MeshStandardMaterial / MeshPhysicalMaterial (what GLTFLoader
// makes for glTF PBR materials) and needs its lookup tables: this plugin calls
// RectAreaLightUniformsLib.init() for WebGLRenderer. (For WebGPURenderer call
// RectAreaLightNode.setLTC( RectAreaLightTexturesLib.init() ) yourself.)
// Lights of type "disk" become a RectAreaLight square of the same area, as Babylon.js does.

import { Color, LinearSRGBColorSpace, RectAreaLight } from 'three';
import { RectAreaLightUniformsLib } from 'three/addons/lights/RectAreaLightUniformsLib.js';

const NAME = 'EXT_lights_area';

let uniformsReady = false;

export class EXTLightsAreaPlugin {

	constructor( parser ) {

		this.parser = parser;
		this.name = NAME;

	}

	// Called by GLTFLoader for every node; returns the light that node places, or null.
	createNodeAttachment( nodeIndex ) {

		const json = this.parser.json;
		const ref = json.nodes[ nodeIndex ].extensions?.[ NAME ];
		if ( ref === undefined || ref.light === undefined ) return null;

		const lights = json.extensions?.[ NAME ]?.lights ?? [];
		const def = lights[ ref.light ];
		if ( def === undefined ) {

			return Promise.reject( new Error( `${ NAME }: node ${ nodeIndex } refers to light ${ ref.light }, but the file has ${ lights.length }` ) );

		}

		if ( ! uniformsReady ) {

			RectAreaLightUniformsLib.init();
			uniformsReady = true;

		}

		// Defaults of the draft: size 1, aspect 1, white, intensity 1000 nits.
		const size = def.size ?? 1;
		let width, height;
		switch ( def.type ) {

			case 'rect':
				height = size;
				width = size * ( def.rect?.aspect ?? 1 );
				break;
			case 'disk':
				width = height = Math.sqrt( Math.PI ) * size / 2; // same area as a disk of diameter `size`
				break;
			default:
				return Promise.reject( new Error( `${ NAME }: light ${ ref.light } has unknown type ${ JSON.stringify( def.type ) }` ) );

		}

		const color = new Color( 1, 1, 1 );
		if ( def.color ) color.setRGB( def.color[ 0 ], def.color[ 1 ], def.color[ 2 ], LinearSRGBColorSpace );

		const light = new RectAreaLight( color, def.intensity ?? 1000, width, height );
		light.name = this.parser.createUniqueName( def.name || `area_light_${ ref.light }` );
		light.userData[ NAME ] = { light: ref.light, node: nodeIndex, type: def.type };
		// The node's translation and rotation are applied to this object (or to the Group that
		// holds it when the node also has a mesh or camera); the light sits at the node origin.
		return Promise.resolve( light );

	}

}
