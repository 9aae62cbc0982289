// Writes the npm package "bunny" (the Stanford bunny: {positions, cells}) as an OBJ, centred on
// the origin in x and z, standing on y = -0.5, scaled to a height of 1.
// Usage: node bunny_to_obj.js PATH/TO/node_modules/bunny OUT.obj
'use strict';
const fs = require('fs');
const [, , modulePath, outPath] = process.argv;
if (!modulePath || !outPath) {
  console.error('usage: node bunny_to_obj.js PATH/TO/node_modules/bunny OUT.obj');
  process.exit(2);
}
const bunny = require(require('path').resolve(modulePath));
const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
for (const p of bunny.positions)
  for (let i = 0; i < 3; ++i) { lo[i] = Math.min(lo[i], p[i]); hi[i] = Math.max(hi[i], p[i]); }
const scale = 1 / (hi[1] - lo[1]);
const centre = [(lo[0] + hi[0]) / 2, lo[1], (lo[2] + hi[2]) / 2];
const lines = ['# The Stanford bunny (Stanford 3D Scanning Repository), from the npm package "bunny" 1.0.1,',
               '# public domain; centred, standing on y = -0.5, height 1.'];
for (const p of bunny.positions)
  lines.push('v ' + [0, 1, 2].map(i => ((p[i] - centre[i]) * scale - (i === 1 ? 0.5 : 0)).toFixed(6)).join(' '));
for (const c of bunny.cells) lines.push('f ' + c.map(i => i + 1).join(' '));
fs.writeFileSync(outPath, lines.join('\n') + '\n');
