// One step of Loop subdivision of the npm "bunny" package (closed, 3674 triangles), written as
// a binary PLY. Made with: npm pack bunny && tar xzf bunny-1.0.1.tgz && node make_bunny.js bunny.ply
// (the package unpacks into ./package, which this script reads).
const b = require("./package");
const P = b.positions, F = b.cells;
const edges = new Map(), nb = P.map(() => new Set());
const key = (a, c) => a < c ? a + "," + c : c + "," + a;
for (const f of F) for (let i = 0; i < 3; i++) {
  const a = f[i], c = f[(i + 1) % 3], o = f[(i + 2) % 3];
  const k = key(a, c); if (!edges.has(k)) edges.set(k, {a, c, opp: []}); edges.get(k).opp.push(o);
  nb[a].add(c); nb[c].add(a);
}
const out = P.map((p, i) => {
  const n = nb[i].size, beta = (5/8 - Math.pow(3/8 + Math.cos(2*Math.PI/n)/4, 2)) / n;
  const s = [0,0,0]; for (const j of nb[i]) for (let k = 0; k < 3; k++) s[k] += P[j][k];
  return [0,1,2].map(k => (1 - n*beta) * p[k] + beta * s[k]);
});
const eid = new Map();
for (const [k, e] of edges) {
  eid.set(k, out.length);
  out.push([0,1,2].map(x => 3/8*(P[e.a][x] + P[e.c][x]) + 1/8*(P[e.opp[0]][x] + P[e.opp[1]][x])));
}
const tris = [];
for (const [a, c, d] of F) {
  const ab = eid.get(key(a, c)), bc = eid.get(key(c, d)), ca = eid.get(key(d, a));
  tris.push([a, ab, ca], [ab, c, bc], [ca, bc, d], [ab, bc, ca]);
}
const hdr = `ply\nformat binary_little_endian 1.0\ncomment The Stanford bunny (Stanford 3D Scanning Repository), as decimated in the npm package "bunny" (public domain), with one step of Loop subdivision\nelement vertex ${out.length}\nproperty float x\nproperty float y\nproperty float z\nelement face ${tris.length}\nproperty list uchar int vertex_indices\nend_header\n`;
const buf = Buffer.alloc(out.length * 12 + tris.length * 13);
let o = 0;
for (const p of out) for (const x of p) { buf.writeFloatLE(x, o); o += 4; }
for (const t of tris) { buf.writeUInt8(3, o); o += 1; for (const x of t) { buf.writeInt32LE(x, o); o += 4; } }
require("fs").writeFileSync(process.argv[2], Buffer.concat([Buffer.from(hdr), buf]));
console.log(out.length, tris.length);
