// node inspect.cjs FILE.glb: prints, one fact a line, what the export tests
// compare with the AFM and the stream, read straight from the GLB (no
// library, so it checks the file independently of three.js):
//   target MESH NAME                 every morph target name, per mesh
//   node NAME PARENT                 the node tree ("-" for a root)
//   keys N                           animation keys
//   weight MESH NAME K VALUE         a morph weight at key K
//   rotation NODE K X Y Z W          a node's animated rotation at key K
'use strict';
const fs = require('fs');

const buf = fs.readFileSync(process.argv[2]);
if (buf.readUInt32LE(0) !== 0x46546c67) throw new Error('not a GLB file');
const jsonLength = buf.readUInt32LE(12);
const gltf = JSON.parse(buf.toString('utf8', 20, 20 + jsonLength));
const binStart = 20 + jsonLength + 8;

// Dense float accessors only (animation data).
function floats(index) {
  const a = gltf.accessors[index];
  const v = gltf.bufferViews[a.bufferView];
  const width = { SCALAR: 1, VEC2: 2, VEC3: 3, VEC4: 4 }[a.type];
  if (a.componentType !== 5126) throw new Error(`accessor ${index} is not float`);
  const out = [];
  for (let i = 0; i < a.count * width; ++i)
    out.push(buf.readFloatLE(binStart + (v.byteOffset || 0) + (a.byteOffset || 0) + 4 * i));
  return out;
}

const lines = [];
gltf.meshes.forEach((m) => {
  for (const t of (m.extras && m.extras.targetNames) || []) lines.push(`target ${m.name} ${t}`);
});
const parent = {};
gltf.nodes.forEach((n, i) => (n.children || []).forEach((c) => (parent[c] = i)));
gltf.nodes.forEach((n, i) => lines.push(`node ${n.name} ${i in parent ? gltf.nodes[parent[i]].name : '-'}`));
for (const anim of gltf.animations || []) {
  let keys = 0;
  for (const c of anim.channels) {
    const s = anim.samplers[c.sampler];
    const input = floats(s.input);
    keys = input.length;
    const out = floats(s.output);
    const node = gltf.nodes[c.target.node];
    if (c.target.path === 'weights') {
      const names = gltf.meshes[node.mesh].extras.targetNames;
      for (let k = 0; k < input.length; ++k)
        names.forEach((name, t) => {
          const w = out[k * names.length + t];
          if (w !== 0) lines.push(`weight ${node.name} ${name} ${k} ${w}`);
        });
    } else if (c.target.path === 'rotation') {
      for (let k = 0; k < input.length; ++k)
        lines.push(`rotation ${node.name} ${k} ${out.slice(4 * k, 4 * k + 4).join(' ')}`);
    }
  }
  lines.push(`keys ${keys}`);
}
console.log(lines.join('\n'));
