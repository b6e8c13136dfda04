// Flatland's occluder scene (scenes/occluder.toml), live: drag the occluder,
// the lamp or the sensor; turn and scale the occluder with the sliders (or
// the wheel: turn; shift+wheel: scale). Drawn: rays sampled from the
// sensor's cosine lobe, and the expectation method's warp field (how each
// ray's end moves with the chosen parameter, as in flat_warp). Every
// method's E and ∂E/∂π converge against the closed form (flat::exact).
import { client, setCell, slider, fmt, COLORS } from "./live.js";

const METHODS = ["intensity", "expectation", "rendering", "transport", "fd"];
const PARAMS = ["occluder_tx", "occluder_ty", "occluder_rotate", "occluder_scale"];
const BASE = { lamp: [[-1.0, 2.0], [1.0, 2.0]], occluder: [[-0.6, 1.0], [0.2, 1.0]], center: [-0.2, 1.0] };

function widget(box) {
  box.classList.add("live-box");
  const st = { lamp: [0, 0], occ: [0, 0], angle: 0, scale: 1, sensor: [0, 0] };
  const controls = document.createElement("div");
  controls.className = "live-controls";
  box.append(controls);
  const rot = slider(controls, { label: "occluder turn (°)", min: -60, max: 60, step: 1, value: 0, name: "rotate" });
  const scl = slider(controls, { label: "occluder scale", min: 0.3, max: 2, step: 0.01, value: 1, name: "scale" });
  const show = document.createElement("select");
  show.name = "warp";
  for (const p of PARAMS) show.add(new Option(`warp field of ${p}`, p));
  const paths = document.createElement("select");
  paths.name = "paths";
  for (const p of [65536, 262144, 1048576, 4194304]) paths.add(new Option(`${p.toLocaleString("en")} paths`, p));
  paths.value = "262144";
  const seed = document.createElement("input");
  Object.assign(seed, { type: "number", name: "seed", value: 1, min: 0, step: 1 });
  seed.style.width = "5em";
  const row = document.createElement("div");
  row.className = "live-row";
  row.append(show, paths, " seed ", seed);
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
  table.innerHTML = `<thead><tr><th>method</th><th>E</th>${PARAMS.map((p) => `<th>∂E/∂${p.replace("occluder_", "")}</th>`).join("")}<th>paths</th></tr></thead>`;
  const body = document.createElement("tbody");
  table.append(body);
  const exactRow = body.insertRow();
  exactRow.insertCell().textContent = "closed form";
  const exactCells = qs.map((q) => Object.assign(exactRow.insertCell(), { className: "live-exact" }));
  exactRow.insertCell();
  const rows = {};
  for (const m of METHODS) {
    const tr = body.insertRow();
    tr.insertCell().textContent = m;
    tr.cells[0].style.color = COLORS[m];
    rows[m] = { cells: qs.map(() => tr.insertCell()), paths: tr.insertCell() };
  }
  box.append(table);
  const status = document.createElement("p");
  status.className = "live-status";
  box.append(status);

  const add = (a, b) => [a[0] + b[0], a[1] + b[1]];
  function occluder() {
    const c = add(BASE.center, st.occ);
    if (st.angle === 0 && st.scale === 1) return { verts: BASE.occluder.map((v) => add(v, st.occ)), c };
    const [co, si] = [Math.cos(st.angle), Math.sin(st.angle)];
    const verts = BASE.occluder.map(([x, y]) => {
      const dx = (x - BASE.center[0]) * st.scale;
      const dy = (y - BASE.center[1]) * st.scale;
      return [c[0] + co * dx - si * dy, c[1] + si * dx + co * dy];
    });
    return { verts, c };
  }
  // The scene in the file's schema (what `geosens flat --scene X.json` reads).
  function scene() {
    const o = occluder();
    return {
      sensor: { kind: "irradiance", point: st.sensor, normal: [0.0, 1.0] },
      shapes: [
        { name: "lamp", vertices: BASE.lamp.map((v) => add(v, st.lamp)), surface: { kind: "emitter", radiance: 1.0 } },
        { name: "occluder", vertices: o.verts, surface: { kind: "absorber" } },
      ],
      parameters: [
        { name: "occluder_tx", shape: "occluder", motion: { kind: "translate_x" } },
        { name: "occluder_ty", shape: "occluder", motion: { kind: "translate_y" } },
        { name: "occluder_rotate", shape: "occluder", motion: { kind: "rotate", pivot: o.c } },
        { name: "occluder_scale", shape: "occluder", motion: { kind: "scale", pivot: o.c } },
      ],
    };
  }

  // World [-1.6, 1.6] × [-0.4, 2.4] on the canvas.
  const S = canvas.width / 3.2;
  const toPx = ([x, y]) => [(x + 1.6) * S, canvas.height - (y + 0.4) * S * (canvas.height / (2.8 * S))];
  const sy = canvas.height / 2.8;
  const P = ([x, y]) => [(x + 1.6) * S, canvas.height - (y + 0.4) * sy];
  const W = ([px, py]) => [px / S - 1.6, (canvas.height - py) / sy - 0.4];
  void toPx;
  let rays = [];
  let warp = null;
  function draw() {
    const ctx = canvas.getContext("2d");
    ctx.clearRect(0, 0, canvas.width, canvas.height);
    const sc = scene();
    ctx.lineWidth = 1;
    ctx.strokeStyle = "rgba(120,120,120,0.25)";
    for (let i = 0; i < rays.length; i += 4) {
      ctx.beginPath();
      ctx.moveTo(...P([rays[i], rays[i + 1]]));
      ctx.lineTo(...P([rays[i + 2], rays[i + 3]]));
      ctx.stroke();
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
    const seg = (vs, color, width) => {
      ctx.strokeStyle = color;
      ctx.lineWidth = width;
      ctx.beginPath();
      vs.forEach((v, i) => (i ? ctx.lineTo(...P(v)) : ctx.moveTo(...P(v))));
      ctx.stroke();
    };
    seg(sc.shapes[0].vertices, "#e6a100", 6);
    seg(sc.shapes[1].vertices, "#000", 5);
    ctx.fillStyle = "#d62728";
    ctx.beginPath();
    ctx.arc(...P(st.sensor), 6, 0, 2 * Math.PI);
    ctx.fill();
    ctx.fillStyle = "#333";
    ctx.font = "12px sans-serif";
    ctx.fillText("drag the lamp, the occluder or the sensor; wheel: turn, shift+wheel: scale", 8, 16);
    ctx.fillText(`blue: the warp field of ${show.value} at the rays' ends (expectation method)`, 8, 32);
  }

  const api = client(box);
  if (!api) return;
  async function restart() {
    const sc = scene();
    const text = JSON.stringify(sc);
    box.dataset.scene = text;
    let exact = null;
    try {
      exact = JSON.parse(await api.call("flat_exact", text));
      rays = await api.call("flat_rays", text, 200, BigInt(Number(seed.value)), 3.0);
      warp = JSON.parse(await api.call("flat_warp", text, 48));
      status.textContent = "";
    } catch (e) {
      status.textContent = `invalid scene: ${e.message}`;
      draw();
      return;
    }
    const ex = [exact.intensity, ...PARAMS.map((p) => exact.sensitivity[p])];
    exactCells.forEach((td, i) => {
      td.textContent = fmt(ex[i], 6);
      td.dataset.quantity = qs[i];
      td.dataset.exact = String(ex[i]);
    });
    draw();
    const n = Number(paths.value);
    box.dataset.request = JSON.stringify({ paths: n, seed: Number(seed.value) });
    const started = performance.now();
    api.run(METHODS.map((m) => ({ key: m, request: { flat: sc, method: m, paths: n, seed: Number(seed.value) } })), (msg) => {
      const r = rows[msg.key];
      if (msg.error) {
        r.paths.textContent = msg.error;
        return;
      }
      const j = JSON.parse(msg.json);
      const es = [j.intensity, ...PARAMS.map((p) => j.sensitivity[p])];
      qs.forEach((q, i) => setCell(r.cells[i], msg.key, q, es[i], j.paths, ex[i]));
      r.paths.textContent = j.paths.toLocaleString("en");
      r.paths.dataset.busy = String(msg.busy);
    }, () => {
      status.textContent = `done in ${((performance.now() - started) / 1000).toFixed(1)} s`;
    });
  }
  let pending;
  const later = () => {
    draw();
    clearTimeout(pending);
    pending = setTimeout(restart, 150);
  };
  rot.addEventListener("input", () => ((st.angle = (Number(rot.value) * Math.PI) / 180), later()));
  scl.addEventListener("input", () => ((st.scale = Number(scl.value)), later()));
  paths.addEventListener("change", later);
  seed.addEventListener("input", later);
  show.addEventListener("change", draw);
  // Dragging: the nearest of the sensor, the occluder's centre, the lamp.
  let drag = null;
  const dist = (a, b) => Math.hypot(a[0] - b[0], a[1] - b[1]);
  canvas.addEventListener("pointerdown", (ev) => {
    const r = canvas.getBoundingClientRect();
    const w = W([((ev.clientX - r.left) * canvas.width) / r.width, ((ev.clientY - r.top) * canvas.height) / r.height]);
    const cands = [
      ["sensor", dist(w, st.sensor)],
      ["occ", dist(w, add(BASE.center, st.occ))],
      ["lamp", Math.abs(w[1] - (2 + st.lamp[1])) + Math.max(0, Math.abs(w[0] - st.lamp[0]) - 1)],
    ].sort((a, b) => a[1] - b[1]);
    if (cands[0][1] > 0.4) return;
    drag = { what: cands[0][0], from: w, start: [...st[cands[0][0]]] };
    canvas.setPointerCapture(ev.pointerId);
  });
  canvas.addEventListener("pointermove", (ev) => {
    if (!drag) return;
    const r = canvas.getBoundingClientRect();
    const w = W([((ev.clientX - r.left) * canvas.width) / r.width, ((ev.clientY - r.top) * canvas.height) / r.height]);
    st[drag.what] = [drag.start[0] + w[0] - drag.from[0], drag.start[1] + w[1] - drag.from[1]];
    later();
  });
  canvas.addEventListener("pointerup", () => (drag = null));
  canvas.addEventListener("wheel", (ev) => {
    ev.preventDefault();
    if (ev.shiftKey) {
      scl.value = Math.min(2, Math.max(0.3, Number(scl.value) * (ev.deltaY > 0 ? 0.95 : 1.05)));
      scl.dispatchEvent(new Event("input"));
    } else {
      rot.value = Number(rot.value) + (ev.deltaY > 0 ? -2 : 2);
      rot.dispatchEvent(new Event("input"));
    }
  });
  draw();
  api.ready.then(restart);
}

for (const box of document.querySelectorAll('.live-widget[data-widget="flat"]')) widget(box);
