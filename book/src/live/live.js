// Shared parts of the live book's widgets: the worker client, the estimates'
// table (one element per estimate with data-method, data-quantity,
// data-mean, data-stderr, data-paths, data-reliable), number formatting and
// plotting helpers. The estimates themselves come from ./worker.js.
const here = new URL(".", import.meta.url);
{
  const css = document.createElement("link");
  css.rel = "stylesheet";
  css.href = new URL("live.css", here).href;
  document.head.append(css);
}

export function fail(box, message) {
  let p = box.querySelector(".live-error");
  if (!p) {
    p = document.createElement("p");
    p.className = "live-error";
    box.prepend(p);
  }
  p.textContent = `This live widget cannot run: ${message}. Build the WebAssembly package ` +
    "(bash web/build.sh) and serve the book over http (bash book/serve.sh); " +
    "a page opened as a file cannot load WebAssembly.";
  box.dataset.state = "error";
}

// A worker and its two kinds of requests: runs (progress per job) and calls.
export function client(box) {
  let worker;
  try {
    worker = new Worker(new URL("worker.js", here), { type: "module" });
  } catch (e) {
    fail(box, String(e));
    return null;
  }
  let runId = 0;
  let callId = 0;
  const calls = new Map();
  let handlers = null;
  const timer = setTimeout(() => fail(box, "the WebAssembly package did not load within 20 s"), 20000);
  const ready = new Promise((resolve) => {
    worker.onmessage = (ev) => {
      const m = ev.data;
      if (m.type === "ready") {
        clearTimeout(timer);
        box.dataset.state = "ready";
        resolve();
      } else if (m.type === "error") {
        clearTimeout(timer);
        fail(box, m.message);
      } else if (m.type === "result") {
        const c = calls.get(m.id);
        calls.delete(m.id);
        if (m.error !== undefined) c.reject(new Error(m.error));
        else c.resolve(m.value);
      } else if (handlers && m.id === runId) {
        if (m.type === "progress") handlers.progress(m);
        else if (m.type === "done") handlers.done();
      }
    };
  });
  worker.onerror = (e) => {
    clearTimeout(timer);
    fail(box, `the worker failed (${e.message || "it or live/pkg/geosens_web.js did not load"})`);
  };
  return {
    ready,
    run(jobs, progress, done = () => {}) {
      runId += 1;
      handlers = { progress, done };
      box.dataset.running = "true";
      const wrapped = () => {
        box.dataset.running = "false";
        done();
      };
      handlers.done = wrapped;
      worker.postMessage({ type: "run", id: runId, jobs });
    },
    call(fn, ...args) {
      callId += 1;
      return new Promise((resolve, reject) => {
        calls.set(callId, { resolve, reject });
        worker.postMessage({ type: "call", id: callId, fn, args });
      });
    },
  };
}

export function fmt(x, digits = 4) {
  if (x === null || x === undefined || Number.isNaN(x)) return "–";
  if (x === 0) return "0";
  const a = Math.abs(x);
  return a >= 1e-3 && a < 1e4 ? x.toPrecision(digits) : x.toExponential(digits - 1);
}

// The cell of one estimate: mean ± stderr, its z against `exact`, and the
// data- attributes the browser test reads.
export function setCell(td, method, quantity, e, paths, exact) {
  td.dataset.method = method;
  td.dataset.quantity = quantity;
  td.classList.add("live-estimate");
  if (!e) {
    td.textContent = "not estimated";
    td.dataset.mean = "";
    td.dataset.stderr = "";
    td.dataset.paths = String(paths);
    td.dataset.reliable = "";
    return;
  }
  td.dataset.mean = String(e.mean);
  td.dataset.stderr = String(e.stderr);
  td.dataset.paths = String(paths);
  td.dataset.reliable = String(e.reliable);
  const z = exact !== undefined && e.stderr > 0 ? (e.mean - exact) / e.stderr : null;
  td.innerHTML = "";
  const v = document.createElement("span");
  v.textContent = `${fmt(e.mean)} ± ${fmt(e.stderr, 2)}`;
  td.append(v);
  const small = document.createElement("small");
  small.textContent = (z === null ? "" : ` z = ${z.toFixed(1)}`) + (e.reliable ? "" : " ⚠ unreliable");
  td.append(small);
  td.title = e.caveat || (e.reliable ? "error bar trusted" : "error bar not trusted (VOV or too few non-zero weights)");
  td.classList.toggle("live-unreliable", !e.reliable);
}

export function slider(parent, { label, min, max, step, value, name }) {
  const row = document.createElement("label");
  row.className = "live-slider";
  const text = document.createElement("span");
  const input = document.createElement("input");
  Object.assign(input, { type: "range", min, max, step, value });
  input.name = name;
  const out = document.createElement("output");
  const show = () => (out.textContent = Number(input.value).toPrecision(3));
  input.addEventListener("input", show);
  show();
  text.innerHTML = label;
  row.append(text, input, out);
  parent.append(row);
  return input;
}

// Plots series [{points: [[x, y], …], color, dash}] and error bars
// [{x, y, err, color, hollow, round, probe}] in the rectangle of `ctx`.
// With `clip`, the y range holds the series and the bars' centres, and
// longer error bars run out of the frame (a flagged run's bar can be 100
// times the curve). `marker`: an x drawn as a dotted vertical line.
// `zero`: whether the y range holds 0.
export function plot(ctx, { x0, y0, w, h }, series, bars = [], title = "", xlabel = "", { clip = false, marker = null, zero = true } = {}) {
  const reach = clip ? bars.map((b) => [b.x, b.y]) : bars.flatMap((b) => [[b.x, b.y - b.err], [b.x, b.y + b.err]]);
  const pts = series.flatMap((s) => s.points).concat(reach);
  let xmin = Math.min(...pts.map((p) => p[0]));
  let xmax = Math.max(...pts.map((p) => p[0]));
  const ys = pts.map((p) => p[1]).filter(Number.isFinite).concat(zero ? [0] : []);
  let ymin = Math.min(...ys);
  let ymax = Math.max(...ys);
  if (ymax === ymin) ymax = ymin + 1;
  if (xmax === xmin) xmax = xmin + 1;
  const pad = 0.08 * (ymax - ymin);
  ymin -= pad;
  ymax += pad;
  const X = (x) => x0 + 40 + ((x - xmin) / (xmax - xmin)) * (w - 50);
  const Y = (y) => y0 + h - 20 - ((y - ymin) / (ymax - ymin)) * (h - 40);
  ctx.save();
  ctx.strokeStyle = "#888";
  ctx.strokeRect(X(xmin), Y(ymax), X(xmax) - X(xmin), Y(ymin) - Y(ymax));
  ctx.beginPath();
  ctx.moveTo(X(xmin), Y(0));
  ctx.lineTo(X(xmax), Y(0));
  ctx.setLineDash([2, 3]);
  ctx.stroke();
  if (marker !== null) {
    ctx.beginPath();
    ctx.moveTo(X(marker), Y(ymin));
    ctx.lineTo(X(marker), Y(ymax));
    ctx.stroke();
  }
  ctx.setLineDash([]);
  ctx.fillStyle = "#444";
  ctx.font = "11px sans-serif";
  ctx.fillText(title, x0 + 44, y0 + 12);
  ctx.fillText(fmt(ymax, 2), x0, Y(ymax) + 4);
  ctx.fillText(fmt(ymin, 2), x0, Y(ymin));
  ctx.fillText(xlabel, x0 + w / 2, y0 + h - 4);
  ctx.beginPath();
  ctx.rect(X(xmin) - 6, Y(ymax), X(xmax) - X(xmin) + 12, Y(ymin) - Y(ymax));
  ctx.clip();
  for (const s of series) {
    ctx.strokeStyle = s.color;
    ctx.setLineDash(s.dash || []);
    ctx.lineWidth = 1.5;
    ctx.beginPath();
    s.points.forEach(([x, y], i) => (i ? ctx.lineTo(X(x), Y(y)) : ctx.moveTo(X(x), Y(y))));
    ctx.stroke();
  }
  ctx.setLineDash([]);
  for (const b of bars) {
    if (!Number.isFinite(b.y)) continue;
    ctx.strokeStyle = b.color;
    ctx.fillStyle = b.color;
    ctx.lineWidth = b.probe ? 2.5 : 1;
    ctx.beginPath();
    ctx.moveTo(X(b.x), Y(b.y - b.err));
    ctx.lineTo(X(b.x), Y(b.y + b.err));
    ctx.stroke();
    ctx.beginPath();
    if (b.round) ctx.arc(X(b.x), Y(b.y), 3, 0, 2 * Math.PI);
    else ctx.rect(X(b.x) - 3, Y(b.y) - 3, 6, 6);
    if (b.hollow) {
      ctx.fillStyle = "#fff";
      ctx.fill();
      ctx.lineWidth = 1.5;
      ctx.stroke();
    } else ctx.fill();
  }
  ctx.restore();
}

export const COLORS = {
  intensity: "#7f7f7f",
  expectation: "#1f77b4",
  rendering: "#d62728",
  transport: "#2ca02c",
  fd: "#9467bd",
};
