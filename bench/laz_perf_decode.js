// laz-perf (npm, WebAssembly) decoding every point of a LAZ file, for read_bench --laz-perf:
//   node laz_perf_decode.js NODE_MODULES_DIR FILE.laz
// prints one bench= line, best of 3 runs (open included, like read_bench's decode phase).
// laz-perf is not a dependency of omicron: install it outside the repository
// (mkdir /tmp/lp && cd /tmp/lp && npm install laz-perf) and pass /tmp/lp/node_modules.
const fs = require('fs');
const path = require('path');
const { createLazPerf } = require(path.join(path.resolve(process.argv[2]), 'laz-perf'));

(async () => {
  const LazPerf = await createLazPerf();
  const file = fs.readFileSync(process.argv[3]);
  const filePointer = LazPerf._malloc(file.length);
  LazPerf.HEAPU8.set(file, filePointer);
  let best = Infinity;
  let count = 0;
  for (let run = 0; run < 3; ++run) {
    const start = process.hrtime.bigint();
    const laszip = new LazPerf.LASZip();
    laszip.open(filePointer, file.length);
    count = laszip.getCount();
    const pointPointer = LazPerf._malloc(laszip.getPointLength());
    for (let i = 0; i < count; ++i) {
      laszip.getPoint(pointPointer);
    }
    LazPerf._free(pointPointer);
    laszip.delete();
    best = Math.min(best, Number(process.hrtime.bigint() - start) / 1e9);
  }
  LazPerf._free(filePointer);
  console.log(`bench=read reader=laz_perf_npm phase=decode threads=1 points=${count} ` +
              `ms=${(best * 1e3).toFixed(1)} mpoints_per_s=${(count / best / 1e6).toFixed(2)}`);
})().catch((error) => {
  console.error(`laz_perf_decode: ${error}`);
  process.exit(1);
});
