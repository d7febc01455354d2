// Independent LAZ decoder for the tests: the npm package `laz-perf` (LASzip compiled to WASM)
// decodes a LAZ file to its raw point records, concatenated, for test_laz.cpp to compare with
// ours byte for byte.
//   node laz_reference_dump.js <node_modules dir> <in.laz> <out.bin>
// Exits 3 when the package cannot be loaded (the test then skips).
const fs = require('fs');
const path = require('path');
const [modules, input, output] = process.argv.slice(2);
let createLazPerf;
try {
  createLazPerf = require(path.join(modules, 'laz-perf')).createLazPerf;
} catch (e) {
  console.error('laz-perf not found under ' + modules);
  process.exit(3);
}
createLazPerf().then((lp) => {
  const file = fs.readFileSync(input);
  const filePtr = lp._malloc(file.length);
  lp.HEAPU8.set(file, filePtr);
  const laz = new lp.LASZip();
  laz.open(filePtr, file.length);
  const count = laz.getCount();
  const length = laz.getPointLength();
  const pointPtr = lp._malloc(length);
  const fd = fs.openSync(output, 'w');
  const batch = Buffer.alloc(length * 4096);
  let inBatch = 0;
  for (let i = 0; i < count; ++i) {
    laz.getPoint(pointPtr);
    batch.set(lp.HEAPU8.subarray(pointPtr, pointPtr + length), inBatch * length);
    if (++inBatch === 4096) fs.writeSync(fd, batch, 0, inBatch * length), (inBatch = 0);
  }
  fs.writeSync(fd, batch, 0, inBatch * length);
  fs.closeSync(fd);
  laz.delete();
  lp._free(pointPtr);
  lp._free(filePtr);
});
