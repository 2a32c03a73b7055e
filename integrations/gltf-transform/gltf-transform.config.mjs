// For the glTF-Transform CLI: `gltf-transform optimize in.glb out.glb --simplify false
// --config node_modules/streaklight-gltf-transform/gltf-transform.config.mjs`. The CLI replaces
// its list of extensions with this one, so it lists glTF-Transform's own as well.
import { ALL_EXTENSIONS } from '@gltf-transform/extensions';
import { EXTLightsArea } from './index.mjs';

export default { extensions: [...ALL_EXTENSIONS, EXTLightsArea] };
