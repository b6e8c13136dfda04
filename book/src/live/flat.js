// Flatland, live. data-widget="flat" (flatland.md): the occluder scene
// (scenes/occluder.toml); drag the lamp, the occluder or the sensor, turn
// and scale the occluder and the lamp with their sliders (or the wheel over
// either: turn; shift+wheel: scale). data-widget="flat-fail" (comparing.md):
// a sensor in an absorbing box that moves in x, its distance to the box's
// moving edge on a slider (the stability figure's second case). Drawn: the
// first paths the chosen method sampled for the seed (recorded by the
// estimator itself, geosens-web's sampled_paths), the expectation method's
// warp field (flat_warp). Every method's E and ∂E/∂π converge against the
// closed form (flat::exact).
import { client, setCell, slider, plot, fmt, COLORS } from "./live.js";

const PRESETS = {
  flat: {
    methods: ["intensity", "expectation", "rendering", "transport", "fd"],
    shapes: {
      lamp: { vertices: [[-1.0, 2.0], [1.0, 2.0]], surface: { kind: "emitter", radiance: 1.0 }, turn: true },
      occluder: { vertices: [[-0.6, 1.0], [0.2, 1.0]], surface: { kind: "absorber" }, turn: true },
    },
    parameters: [
      ["occluder_tx", "occluder", "translate_x"],
      ["occluder_ty", "occluder", "translate_y"],
      ["occluder_rotate", "occluder", "rotate"],
      ["occluder_scale", "occluder", "scale"],
    ],
    paths: 262144,
    view: [-1.6, -0.4, 3.2, 2.8],
    drag: true,
  },
  "flat-fail": {
    methods: ["expectation", "rendering", "transport", "fd"],
    shapes: {
      lamp: { vertices: [[-1.0, 2.0], [1.0, 2.0]], surface: { kind: "emitter", radiance: 1.0 } },
      box: {
        vertices: [[0.0, -0.5], [1.5, -0.5], [1.5, 1.5], [0.0, 1.5]],
        closed: true,
        surface: { kind: "transparent" },
        medium: { ks: 0.0, ke: 1.0, phase: { kind: "isotropic" } },
      },
    },
    parameters: [["box_tx", "box", "translate_x"]],
    paths: 65536,
    view: [-1.3, -0.7, 3.0, 3.1],
    drag: false,
  },
};
const PATHS = [4096, 16384, 65536, 262144, 1048576, 4194304];
// Paths drawn, and how far an escaping path's last leg is drawn.
const DRAWN = 24;

function widget(box) {
  const preset = PRESETS[box.dataset.widget];
  const fail = box.dataset.widget === "flat-fail";
  const PARAMS = preset.parameters.map((p) => p[0]);
  box.classList.add("live-box");
  // Each shape: its offset, turn (radians) and scale about its centre.
  const st = { sensor: [0, 0], shapes: {} };
  for (const [name, sh] of Object.entries(preset.shapes)) {
    const n = sh.vertices.length;
    const c = [sh.vertices.reduce((a, v) => a + v[0], 0) / n, sh.vertices.reduce((a, v) => a + v[1], 0) / n];
    st.shapes[name] = { off: [0, 0], angle: 0, scale: 1, centre: c };
  }
  const controls = document.createElement("div");
  controls.className = "live-controls";
  box.append(controls);
  const turns = {};
  for (const [name, sh] of Object.entries(preset.shapes)) {
    if (!sh.turn) continue;
    turns[name] = {
      rot: slider(controls, { label: `${name} turn (°)`, min: -60, max: 60, step: 1, value: 0, name: `${name}_rotate` }),
      scl: slider(controls, { label: `${name} scale`, min: 0.3, max: 2, step: 0.01, value: 1, name: `${name}_scale` }),
    };
  }
  // The sensor's distance to the box's moving edge, log10 d.
  const gap = fail
    ? slider(controls, { label: "log<sub>10</sub> d (sensor to the moving edge)", min: -6, max: -0.3, step: 0.1, value: -0.5, name: "log_d" })
    : null;
  const show = document.createElement("select");
  show.name = "warp";
  for (const p of PARAMS) show.add(new Option(`warp field of ${p}`, p));
  const drawnBy = document.createElement("select");
  drawnBy.name = "drawn";
  for (const m of preset.methods) drawnBy.add(new Option(`paths of ${m}`, m));
  drawnBy.value = "expectation";
  const paths = document.createElement("select");
  paths.name = "paths";
  for (const p of PATHS) paths.add(new Option(`${p.toLocaleString("en")} paths`, p));
  paths.value = String(preset.paths);
  const seed = document.createElement("input");
  Object.assign(seed, { type: "number", name: "seed", value: 1, min: 0, step: 1 });
  seed.style.width = "5em";
  const row = document.createElement("div");
  row.className = "live-row";
  row.append(show, drawnBy, paths, " seed ", seed);
  controls.append(row);
  const canvas = document.createElement("canvas");
  canvas.width = 640;
  canvas.height = 400;
  canvas.className = "live-canvas";
  canvas.style.touchAction = "none";
  box.append(canvas);
  const table = document.createElement("table");
  table.className = "live-table";
  const qs = ["intensity", ...PARAMS.map((p) => `sensitivity:${p}`)];
  table.innerHTML = `<thead><tr><th>method</th><th>E</th>${PARAMS.map((p) => `<th>∂E/∂${p}</th>`).join("")}<th>paths</th></tr></thead>`;
  const body = document.createElement("tbody");
  table.append(body);
  const exactRow = body.insertRow();
  exactRow.insertCell().textContent = "closed form";
  const exactCells = qs.map(() => Object.assign(exactRow.insertCell(), { className: "live-exact" }));
  exactRow.insertCell();
  const rows = {};
  for (const m of preset.methods) {
    const tr = body.insertRow();
    tr.insertCell().textContent = m;
    tr.cells[0].style.color = COLORS[m];
    rows[m] = { cells: qs.map(() => tr.insertCell()), paths: tr.insertCell(), json: null };
  }
  box.append(table);
  // flat-fail: each method's ∂E/∂π ± 2σ against the closed form.
  const bars = fail ? Object.assign(document.createElement("canvas"), { width: 640, height: 200, className: "live-canvas" }) : null;
  if (bars) box.append(bars);
  const status = document.createElement("p");
  status.className = "live-status";
  box.append(status);

  const add = (a, b) => [a[0] + b[0], a[1] + b[1]];
  function vertices(name) {
    const sh = preset.shapes[name];
    const s = st.shapes[name];
    let vs = sh.vertices;
    if (fail && name === "box") vs = vs.map(([x, y]) => [x - 10 ** Number(gap.value), y]);
    const c = add(s.centre, s.off);
    if (s.angle === 0 && s.scale === 1) return vs.map((v) => add(v, s.off));
    const [co, si] = [Math.cos(s.angle), Math.sin(s.angle)];
    return vs.map(([x, y]) => {
      const dx = (x - s.centre[0]) * s.scale;
      const dy = (y - s.centre[1]) * s.scale;
      return [c[0] + co * dx - si * dy, c[1] + si * dx + co * dy];
    });
  }
  // The scene in the file's schema (what `geosens flat --scene X.json` reads).
  function scene() {
    const shapes = Object.entries(preset.shapes).map(([name, sh]) => {
      const out = { name, vertices: vertices(name), surface: sh.surface };
      if (sh.closed) out.closed = true;
      if (sh.medium) out.medium = sh.medium;
      return out;
    });
    const parameters = preset.parameters.map(([name, shape, kind]) => {
      const motion = { kind };
      if (kind === "rotate" || kind === "scale") motion.pivot = add(st.shapes[shape].centre, st.shapes[shape].off);
      return { name, shape, motion };
    });
    return { sensor: { kind: "irradiance", point: st.sensor, normal: [0.0, 1.0] }, shapes, parameters };
  }

  const [vx, vy, vw, vh] = preset.view;
  const sx = canvas.width / vw;
  const sy = canvas.height / vh;
  const P = ([x, y]) => [(x - vx) * sx, canvas.height - (y - vy) * sy];
  const W = ([px, py]) => [px / sx + vx, (canvas.height - py) / sy + vy];
  let drawn = null;
  let warp = null;
  function draw() {
    const ctx = canvas.getContext("2d");
    ctx.clearRect(0, 0, canvas.width, canvas.height);
    const sc = scene();
    for (const s of sc.shapes) {
      if (!s.medium) continue;
      ctx.fillStyle = "rgba(90,120,200,0.12)";
      ctx.beginPath();
      s.vertices.forEach((v, i) => (i ? ctx.lineTo(...P(v)) : ctx.moveTo(...P(v))));
      ctx.closePath();
      ctx.fill();
    }
    if (drawn) {
      // One polyline per walk: solid the path from the sensor (amber where
      // it collected light), dashed the walks it nested.
      const vs = drawn.vertices;
      let i = 0;
      while (i < vs.length) {
        const [path, walk] = [vs[i], vs[i + 1]];
        ctx.beginPath();
        ctx.moveTo(...P([vs[i + 2], vs[i + 3]]));
        let j = i + 5;
        for (; j < vs.length && vs[j] === path && vs[j + 1] === walk; j += 5) ctx.lineTo(...P([vs[j + 2], vs[j + 3]]));
        const lit = drawn.weights[path] && drawn.weights[path][0] > 0;
        ctx.strokeStyle = lit ? "rgba(230,140,0,0.7)" : "rgba(110,110,110,0.45)";
        ctx.lineWidth = walk === 0 ? 1.2 : 0.8;
        ctx.setLineDash(walk === 0 ? [] : [3, 3]);
        ctx.stroke();
        i = j;
      }
      ctx.setLineDash([]);
    }
    if (warp) {
      const p = show.value;
      const longest = Math.max(1e-12, ...warp.rays.filter((r) => r.end).map((r) => Math.hypot(...r.arrows[p])));
      const k = 0.3 / longest;
      ctx.strokeStyle = "#1f77b4";
      ctx.lineWidth = 1.5;
      for (const r of warp.rays) {
        if (!r.end) continue;
        const a = r.arrows[p];
        ctx.beginPath();
        ctx.moveTo(...P(r.end));
        ctx.lineTo(...P([r.end[0] + k * a[0], r.end[1] + k * a[1]]));
        ctx.stroke();
      }
    }
    for (const s of sc.shapes) {
      ctx.strokeStyle = s.surface.kind === "emitter" ? "#e6a100" : s.medium ? "#5a78c8" : "#000";
      ctx.lineWidth = s.surface.kind === "emitter" ? 6 : s.medium ? 2 : 5;
      ctx.beginPath();
      s.vertices.forEach((v, i) => (i ? ctx.lineTo(...P(v)) : ctx.moveTo(...P(v))));
      if (s.closed) ctx.closePath();
      ctx.stroke();
    }
    ctx.fillStyle = "#d62728";
    ctx.beginPath();
    ctx.arc(...P(st.sensor), 6, 0, 2 * Math.PI);
    ctx.fill();
    ctx.fillStyle = "#333";
    ctx.font = "12px sans-serif";
    ctx.fillText(
      preset.drag
        ? "drag the lamp, the occluder or the sensor; wheel over the lamp or the occluder: turn, shift+wheel: scale"
        : `the box moves in x; the sensor sits d = ${fmt(10 ** Number(gap.value), 2)} from its left edge`,
      8,
      16,
    );
    ctx.fillText(`lines: the first ${DRAWN} paths ${drawnBy.value} sampled (amber: light collected); blue: the warp field of ${show.value}`, 8, 32);
  }

  function drawBars() {
    if (!bars) return;
    const ctx = bars.getContext("2d");
    ctx.clearRect(0, 0, bars.width, bars.height);
    const ex = Number(exactCells[1].dataset.exact);
    const b = [];
    preset.methods.forEach((m, i) => {
      const e = rows[m].json && rows[m].json.sensitivity[PARAMS[0]];
      if (e) b.push({ x: i, y: e.mean, err: 2 * e.stderr, color: COLORS[m], hollow: !e.reliable });
    });
    const n = preset.methods.length;
    const line = Number.isFinite(ex) ? [{ points: [[-0.5, ex], [n - 0.5, ex]], color: "#333", dash: [4, 3] }] : [];
    plot(ctx, { x0: 0, y0: 0, w: bars.width, h: bars.height }, line, b,
      `∂E/∂${PARAMS[0]} ±2σ by ${preset.methods.join(", ")} (left to right); dashed: the closed form; hollow: flagged`,
      "", { zero: false });
  }

  const api = client(box);
  if (!api) return;
  async function restart() {
    const sc = scene();
    const text = JSON.stringify(sc);
    box.dataset.scene = text;
    const sd = Number(seed.value);
    let exact = null;
    try {
      exact = JSON.parse(await api.call("flat_exact", text));
      warp = JSON.parse(await api.call("flat_warp", text, 48));
      status.textContent = "";
    } catch (e) {
      status.textContent = `invalid scene: ${e.message}`;
      draw();
      return;
    }
    redrawPaths();
    const ex = [exact.intensity, ...PARAMS.map((p) => exact.sensitivity[p])];
    exactCells.forEach((td, i) => {
      td.textContent = fmt(ex[i], 6);
      td.dataset.quantity = qs[i];
      td.dataset.exact = String(ex[i]);
    });
    draw();
    const n = Number(paths.value);
    box.dataset.request = JSON.stringify({ paths: n, seed: sd });
    for (const m of preset.methods) rows[m].json = null;
    const started = performance.now();
    api.run(preset.methods.map((m) => ({ key: m, request: { flat: sc, method: m, paths: n, seed: sd } })), (msg) => {
      const r = rows[msg.key];
      if (msg.error) {
        r.paths.textContent = msg.error;
        return;
      }
      const j = JSON.parse(msg.json);
      r.json = j;
      const es = [j.intensity, ...PARAMS.map((p) => j.sensitivity[p])];
      qs.forEach((q, i) => setCell(r.cells[i], msg.key, q, es[i], j.paths, ex[i]));
      r.paths.textContent = j.paths.toLocaleString("en");
      r.paths.dataset.busy = String(msg.busy);
      drawBars();
    }, () => {
      status.textContent = `done in ${((performance.now() - started) / 1000).toFixed(1)} s`;
    });
  }
  // The paths the chosen method sampled first, for this scene and seed.
  async function redrawPaths() {
    const text = box.dataset.scene;
    const request = JSON.stringify({ flat: JSON.parse(text), method: drawnBy.value, seed: Number(seed.value) });
    try {
      const got = JSON.parse(await api.call("sampled_paths", request, DRAWN));
      if (box.dataset.scene !== text) return;
      drawn = got;
      canvas.dataset.drawn = JSON.stringify({ request: JSON.parse(request), n: DRAWN, vertices: got.vertices });
    } catch (e) {
      drawn = null;
      status.textContent = `no paths drawn: ${e.message}`;
    }
    draw();
  }
  let pending;
  const later = () => {
    draw();
    clearTimeout(pending);
    pending = setTimeout(restart, 150);
  };
  for (const [name, t] of Object.entries(turns)) {
    t.rot.addEventListener("input", () => ((st.shapes[name].angle = (Number(t.rot.value) * Math.PI) / 180), later()));
    t.scl.addEventListener("input", () => ((st.shapes[name].scale = Number(t.scl.value)), later()));
  }
  if (gap) gap.addEventListener("input", later);
  paths.addEventListener("change", later);
  seed.addEventListener("input", later);
  show.addEventListener("change", draw);
  drawnBy.addEventListener("change", redrawPaths);
  if (preset.drag) {
    // Dragging: the nearest of the sensor and the shapes' centres (the lamp:
    // anywhere along it); the wheel turns or scales the nearest shape.
    let drag = null;
    const dist = (a, b) => Math.hypot(a[0] - b[0], a[1] - b[1]);
    const at = (ev) => {
      const r = canvas.getBoundingClientRect();
      return W([((ev.clientX - r.left) * canvas.width) / r.width, ((ev.clientY - r.top) * canvas.height) / r.height]);
    };
    const toSegment = (w, [a, b]) => {
      const d = [b[0] - a[0], b[1] - a[1]];
      const t = Math.max(0, Math.min(1, ((w[0] - a[0]) * d[0] + (w[1] - a[1]) * d[1]) / (d[0] * d[0] + d[1] * d[1])));
      return dist(w, [a[0] + t * d[0], a[1] + t * d[1]]);
    };
    const nearest = (w, shapesOnly) => {
      const cands = Object.keys(preset.shapes).map((name) => {
        const vs = vertices(name);
        const d = name === "lamp" ? toSegment(w, vs) : dist(w, add(st.shapes[name].centre, st.shapes[name].off));
        return [name, d];
      });
      if (!shapesOnly) cands.push(["sensor", dist(w, st.sensor)]);
      return cands.sort((a, b) => a[1] - b[1])[0];
    };
    canvas.addEventListener("pointerdown", (ev) => {
      const w = at(ev);
      const [what, d] = nearest(w, false);
      if (d > 0.4) return;
      const start = what === "sensor" ? [...st.sensor] : [...st.shapes[what].off];
      drag = { what, from: w, start };
      canvas.setPointerCapture(ev.pointerId);
    });
    canvas.addEventListener("pointermove", (ev) => {
      if (!drag) return;
      const w = at(ev);
      const moved = [drag.start[0] + w[0] - drag.from[0], drag.start[1] + w[1] - drag.from[1]];
      if (drag.what === "sensor") st.sensor = moved;
      else st.shapes[drag.what].off = moved;
      later();
    });
    canvas.addEventListener("pointerup", () => (drag = null));
    canvas.addEventListener("wheel", (ev) => {
      const [what] = nearest(at(ev), true);
      const t = turns[what];
      if (!t) return;
      ev.preventDefault();
      if (ev.shiftKey) {
        t.scl.value = Math.min(2, Math.max(0.3, Number(t.scl.value) * (ev.deltaY > 0 ? 0.95 : 1.05)));
        t.scl.dispatchEvent(new Event("input"));
      } else {
        t.rot.value = Number(t.rot.value) + (ev.deltaY > 0 ? -2 : 2);
        t.rot.dispatchEvent(new Event("input"));
      }
    });
  }
  draw();
  api.ready.then(restart);
}

for (const box of document.querySelectorAll('.live-widget[data-widget^="flat"]')) widget(box);
