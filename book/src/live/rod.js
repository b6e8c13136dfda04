// The rod, live: every method's estimates of I, ∂I/∂π̃ (and the transport
// model's ∂I/∂x) at the probe, growing in paths against the Bellman–Wing
// values, and the paper's Figs. 5 and 6 redrawn as the sliders move: the
// exact curves along the rod for ω = ±1 (geosens-web's rod_curves) with
// every method's estimates at nine points on them (±2σ; a hollow marker is
// an error bar the estimator flags). Used by rod.md (data-widget="rod") and
// comparing.md (data-widget="rod-fail": a thin rod, small runs, the probe
// near the moving end).
import { client, setCell, slider, plot, fmt, COLORS } from "./live.js";

const QUANTITIES = [
  ["intensity", "I"],
  ["sensitivity", "∂I/∂π̃"],
  ["gradient_x", "∂I/∂x"],
];
// Points along the rod where the curves are estimated: x = π̃ i/8.
const POINTS = 9;
// Samples of the exact curves: x = π̃ i/(CURVE − 1), the points above among them.
const CURVE = 201;
const PATHS = [4096, 16384, 65536, 262144, 1048576, 4194304, 16777216];
const PRESETS = {
  rod: {
    methods: ["intensity", "expectation", "rendering", "transport", "fd"],
    values: { ks: 0.5, ke: 1, length: 2, x: 0.7, omega: 1 },
    paths: 1048576,
    pointPaths: 65536,
    xStep: 0.005,
  },
  "rod-fail": {
    methods: ["expectation", "rendering", "transport"],
    values: { ks: 0.07, ke: 0.1, length: 2, x: 1.96, omega: 1 },
    paths: 4096,
    pointPaths: 4096,
    xStep: 0.0005,
  },
};

function widget(box) {
  const preset = PRESETS[box.dataset.widget];
  const v = preset.values;
  box.classList.add("live-box");
  const controls = document.createElement("div");
  controls.className = "live-controls";
  box.append(controls);
  const s = {
    ks: slider(controls, { label: "κ<sub>s</sub>", min: 0, max: 4, step: 0.01, value: v.ks, name: "ks" }),
    ke: slider(controls, { label: "κ<sub>e</sub>", min: 0.01, max: 4, step: 0.01, value: v.ke, name: "ke" }),
    length: slider(controls, { label: "length π̃", min: 0.1, max: 5, step: 0.01, value: v.length, name: "length" }),
    x: slider(controls, { label: "probe x / π̃", min: 0, max: 1, step: preset.xStep, value: v.x / v.length, name: "x" }),
  };
  const omega = document.createElement("select");
  omega.name = "omega";
  omega.innerHTML = '<option value="1">ω = +1 (looks right)</option><option value="-1">ω = −1 (looks left)</option>';
  omega.value = String(v.omega);
  const choice = (name, value, label) => {
    const el = document.createElement("select");
    el.name = name;
    for (const p of PATHS) el.add(new Option(`${p.toLocaleString("en")} ${label}`, p));
    el.value = String(value);
    return el;
  };
  const paths = choice("paths", preset.paths, "paths at the probe");
  const pointPaths = choice("point_paths", preset.pointPaths, "paths per curve point");
  const seed = document.createElement("input");
  Object.assign(seed, { type: "number", name: "seed", value: 1, min: 0, step: 1 });
  seed.style.width = "5em";
  const extra = document.createElement("div");
  extra.className = "live-row";
  extra.append(omega, paths, pointPaths, " seed ", seed);
  controls.append(extra);

  const table = document.createElement("table");
  table.className = "live-table";
  table.innerHTML = `<thead><tr><th>method</th>${QUANTITIES.map((q) => `<th>${q[1]}</th>`).join("")}<th>paths</th></tr></thead>`;
  const body = document.createElement("tbody");
  table.append(body);
  const exactRow = body.insertRow();
  exactRow.insertCell().textContent = "exact (Bellman–Wing)";
  const exactCells = QUANTITIES.map(([q]) => {
    const td = exactRow.insertCell();
    td.className = "live-exact";
    td.dataset.quantity = q;
    return td;
  });
  exactRow.insertCell();
  const rows = {};
  for (const m of preset.methods) {
    const tr = body.insertRow();
    tr.insertCell().textContent = m;
    tr.cells[0].style.color = COLORS[m];
    rows[m] = { cells: QUANTITIES.map(() => tr.insertCell()), paths: tr.insertCell(), json: null };
  }
  const canvas = document.createElement("canvas");
  canvas.width = 720;
  canvas.height = 260;
  canvas.className = "live-canvas";
  // The estimates on the curves, one cell each (folded: the figure shows them).
  const details = document.createElement("details");
  details.innerHTML = "<summary>the estimates on the curves</summary>";
  const pointTable = document.createElement("table");
  pointTable.className = "live-table live-points";
  pointTable.innerHTML = "<thead><tr><th>method</th><th>ω</th><th>x</th><th>I</th><th>∂I/∂π̃</th></tr></thead>";
  const pointBody = document.createElement("tbody");
  pointTable.append(pointBody);
  details.append(pointTable);
  box.append(table, canvas, details);
  const status = document.createElement("p");
  status.className = "live-status";
  box.append(status);

  const api = client(box);
  if (!api) return;
  let exact = [];
  let curves = null;
  // Per curve-point job key: {method, omega, x, json, cells}.
  let points = {};

  const probe = () => {
    let ks = Number(s.ks.value);
    const ke = Number(s.ke.value);
    if (ks > ke) {
      ks = ke;
      s.ks.value = ks;
      s.ks.dispatchEvent(new Event("input"));
    }
    const length = Number(s.length.value);
    return { ks, ke, length, x: Number(s.x.value) * length, omega: Number(omega.value) };
  };

  function draw() {
    const ctx = canvas.getContext("2d");
    ctx.clearRect(0, 0, canvas.width, canvas.height);
    if (!curves) return;
    const p = probe();
    const dirs = [["right", 1, []], ["left", -1, [5, 4]]];
    const nm = preset.methods.length;
    const panel = (key, qi, rect, title) => {
      const series = dirs.map(([d, , dash]) => ({ points: curves.x.map((x, i) => [x, curves[d][key][i]]), color: "#333", dash }));
      const bars = [];
      for (const pt of Object.values(points)) {
        const e = pt.json && pt.json[key];
        if (!e) continue;
        // Methods side by side around their point.
        const dx = ((preset.methods.indexOf(pt.method) - (nm - 1) / 2) * p.length) / 120;
        bars.push({ x: pt.x + dx, y: e.mean, err: 2 * e.stderr, color: COLORS[pt.method], hollow: !e.reliable, round: pt.omega < 0 });
      }
      for (const m of preset.methods) {
        const e = rows[m].json && rows[m].json[QUANTITIES[qi][0]];
        if (e) bars.push({ x: p.x, y: e.mean, err: 2 * e.stderr, color: COLORS[m], hollow: !e.reliable, probe: true });
      }
      plot(ctx, rect, series, bars, title, "x", { clip: true, marker: p.x });
    };
    panel("intensity", 0, { x0: 0, y0: 0, w: 360, h: 260 }, "I(x) (Fig. 5): exact ω=+1 solid, ω=−1 dashed; ■ ω=+1, ● ω=−1 ±2σ");
    panel("sensitivity", 1, { x0: 360, y0: 0, w: 360, h: 260 }, "∂I/∂π̃(x) (Fig. 6); hollow: flagged; | the probe");
  }

  function pointRows(p) {
    pointBody.innerHTML = "";
    points = {};
    for (const m of preset.methods) {
      for (const om of [1, -1]) {
        for (let i = 0; i < POINTS; i++) {
          const x = (p.length * i) / (POINTS - 1);
          const tr = pointBody.insertRow();
          tr.insertCell().textContent = m;
          tr.insertCell().textContent = om > 0 ? "+1" : "−1";
          tr.insertCell().textContent = fmt(x, 3);
          const cells = [tr.insertCell(), tr.insertCell()];
          for (const td of cells) {
            td.dataset.x = String(x);
            td.dataset.omega = String(om);
          }
          points[`point:${m}:${om}:${i}`] = { method: m, omega: om, x, i, json: null, cells };
        }
      }
    }
  }

  async function restart() {
    const p = probe();
    try {
      exact = await api.call("rod_exact", JSON.stringify(p));
      curves = JSON.parse(await api.call("rod_curves", p.ks, p.ke, p.length, CURVE));
      status.textContent = "";
    } catch (e) {
      status.textContent = `invalid rod: ${e.message}`;
      return;
    }
    canvas.dataset.curves = JSON.stringify({ ks: p.ks, ke: p.ke, length: p.length, ...curves });
    exactCells.forEach((td, i) => {
      td.textContent = fmt(exact[i], 6);
      td.dataset.exact = String(exact[i]);
    });
    for (const m of preset.methods) rows[m].json = null;
    pointRows(p);
    const n = Number(paths.value);
    const np = Number(pointPaths.value);
    const sd = Number(seed.value);
    const jobs = preset.methods.map((m) => ({ key: m, request: { rod: p, method: m, paths: n, seed: sd } }));
    for (const [key, pt] of Object.entries(points)) {
      const rod = { ks: p.ks, ke: p.ke, length: p.length, x: pt.x, omega: pt.omega };
      jobs.push({ key, request: { rod, method: pt.method, paths: np, seed: sd } });
    }
    box.dataset.request = JSON.stringify({ rod: p, paths: n, point_paths: np, seed: sd });
    const started = performance.now();
    api.run(jobs, (msg) => {
      const pt = points[msg.key];
      const r = rows[msg.key];
      if (msg.error) {
        // fd, say, cannot shorten the rod past a probe at its end.
        if (r) r.paths.textContent = msg.error;
        for (const td of pt ? pt.cells : []) Object.assign(td, { textContent: "–", title: msg.error }).dataset.error = msg.error;
        return;
      }
      const j = JSON.parse(msg.json);
      if (pt) {
        pt.json = j;
        const ex = (q) => curves[pt.omega > 0 ? "right" : "left"][q][(pt.i * (CURVE - 1)) / (POINTS - 1)];
        setCell(pt.cells[0], pt.method, "intensity", j.intensity, j.paths, ex("intensity"));
        setCell(pt.cells[1], pt.method, "sensitivity", j.sensitivity, j.paths, ex("sensitivity"));
      } else {
        r.json = j;
        QUANTITIES.forEach(([q], i) => setCell(r.cells[i], msg.key, q, j[q], j.paths, exact[i]));
        r.paths.textContent = j.paths.toLocaleString("en");
        r.paths.dataset.busy = String(msg.busy);
      }
      draw();
    }, () => {
      status.textContent = `done in ${((performance.now() - started) / 1000).toFixed(1)} s (one worker, runs in turn, a block of 65 536 paths each).`;
    });
    draw();
  }
  let pending;
  const later = () => {
    clearTimeout(pending);
    pending = setTimeout(restart, 150);
  };
  for (const el of [...Object.values(s), omega, paths, pointPaths, seed]) el.addEventListener(el.tagName === "SELECT" ? "change" : "input", later);
  api.ready.then(restart);
}

for (const box of document.querySelectorAll('.live-widget[data-widget^="rod"]')) widget(box);
