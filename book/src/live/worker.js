// The live book's Web Worker: runs the geosens estimators (WebAssembly, built
// from web/ into ./pkg by web/build.sh) off the page's thread. Nothing is
// estimated in JavaScript: a run is geosens-web's `Run`, sampled a block of
// 65 536 paths at a time, whose JSON line is the command line's.
//
// Messages in:  {type: "run", id, jobs: [{key, request}]}  (a new run cancels the old)
//               {type: "call", id, fn, args}                (rod_curves, flat_exact, …)
// Messages out: {type: "ready"} | {type: "error", message}
//               {type: "progress", id, key, json, busy}     (busy: seconds in `step`)
//               {type: "done", id} | {type: "result", id, value, error}
import init, * as geosens from "./pkg/geosens_web.js";

let current = 0;
const loaded = init()
  .then(() => postMessage({ type: "ready" }))
  .catch((e) => {
    postMessage({ type: "error", message: `cannot load the WebAssembly package (live/pkg): ${e}` });
    throw e;
  });

const pause = () => new Promise((r) => setTimeout(r, 0));

async function run(id, jobs) {
  const runs = [];
  for (const job of jobs) {
    try {
      runs.push({ key: job.key, run: new geosens.Run(JSON.stringify(job.request)), busy: 0, done: false });
    } catch (e) {
      postMessage({ type: "progress", id, key: job.key, error: String(e.message || e) });
    }
  }
  while (runs.some((r) => !r.done)) {
    for (const r of runs) {
      if (r.done) continue;
      const t0 = performance.now();
      r.done = r.run.step(1);
      r.busy += (performance.now() - t0) / 1000;
      postMessage({ type: "progress", id, key: r.key, json: r.run.json(), busy: r.busy });
      await pause(); // lets a newer run's message in
      if (id !== current) {
        runs.forEach((x) => x.run.free());
        return;
      }
    }
  }
  runs.forEach((x) => x.run.free());
  postMessage({ type: "done", id });
}

onmessage = async (ev) => {
  const m = ev.data;
  await loaded;
  if (m.type === "run") {
    current = m.id;
    run(m.id, m.jobs);
  } else if (m.type === "call") {
    try {
      postMessage({ type: "result", id: m.id, value: geosens[m.fn](...m.args) });
    } catch (e) {
      postMessage({ type: "result", id: m.id, error: String(e.message || e) });
    }
  }
};
