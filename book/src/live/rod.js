// The rod, live: every method's estimates of I, ∂I/∂π̃ (and the transport
// model's ∂I/∂x) growing in paths against the Bellman–Wing values, and the
// exact curves along the rod (the paper's Figs. 5 and 6) redrawn as the
// sliders move. Used by rod.md (data-widget="rod") and comparing.md
// (data-widget="rod-fail": the probe near the moving end, a thin rod).
import { client, setCell, slider, plot, fmt, COLORS } from "./live.js";

const QUANTITIES = [
  ["intensity", "I"],
  ["sensitivity", "∂I/∂π̃"],
  ["gradient_x", "∂I/∂x"],
];
const PRESETS = {
  rod: {
    methods: ["intensity", "expectation", "rendering", "transport", "fd"],
    values: { ks: 0.5, ke: 1, length: 2, x: 0.7, omega: 1 },
    paths: 1048576,
  },
  "rod-fail": {
    methods: ["expectation", "rendering", "transport"],
    values: { ks: 0.09, ke: 0.1, length: 1, x: 0.98, omega: 1 },
    paths: 262144,
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
    x: slider(controls, { label: "probe x / π̃", min: 0, max: 1, step: 0.005, value: v.x / v.length, name: "x" }),
  };
  const omega = document.createElement("select");
  omega.name = "omega";
  omega.innerHTML = '<option value="1">ω = +1 (looks right)</option><option value="-1">ω = −1 (looks left)</option>';
  omega.value = String(v.omega);
  const paths = document.createElement("select");
  paths.name = "paths";
  for (const p of [65536, 262144, 1048576, 4194304, 16777216]) paths.add(new Option(`${p.toLocaleString("en")} paths`, p));
  paths.value = String(preset.paths);
  const seed = document.createElement("input");
  Object.assign(seed, { type: "number", name: "seed", value: 1, min: 0, step: 1 });
  seed.style.width = "5em";
  const extra = document.createElement("div");
  extra.className = "live-row";
  extra.append(omega, paths, " seed ", seed);
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
  canvas.height = 240;
  canvas.className = "live-canvas";
  box.append(table, canvas);
  const status = document.createElement("p");
  status.className = "live-status";
  box.append(status);

  const api = client(box);
  if (!api) return;
  let exact = [];
  let curves = null;

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
    const dirs = [["right", "#333", []], ["left", "#333", [5, 4]]];
    const panel = (key, qi, rect, title) => {
      const series = dirs.map(([d, c, dash]) => ({ points: curves.x.map((x, i) => [x, curves[d][key][i]]), color: c, dash }));
      const bars = [];
      for (const m of preset.methods) {
        const e = rows[m].json && rows[m].json[QUANTITIES[qi][0]];
        if (e) bars.push({ x: p.x, y: e.mean, err: 2 * e.stderr, color: COLORS[m] });
      }
      plot(ctx, rect, series, bars, title, "x");
    };
    panel("intensity", 0, { x0: 0, y0: 0, w: 360, h: 240 }, "I(x): exact, ω=+1 solid, ω=−1 dashed (Fig. 5); ±2σ at the probe");
    panel("sensitivity", 1, { x0: 360, y0: 0, w: 360, h: 240 }, "∂I/∂π̃(x) (Fig. 6)");
  }

  async function restart() {
    const p = probe();
    try {
      exact = await api.call("rod_exact", JSON.stringify(p));
      curves = JSON.parse(await api.call("rod_curves", p.ks, p.ke, p.length, 201));
      status.textContent = "";
    } catch (e) {
      status.textContent = `invalid rod: ${e.message}`;
      return;
    }
    exactCells.forEach((td, i) => {
      td.textContent = fmt(exact[i], 6);
      td.dataset.exact = String(exact[i]);
    });
    for (const m of preset.methods) rows[m].json = null;
    const jobs = preset.methods.map((m) => ({
      key: m,
      request: { rod: p, method: m, paths: Number(paths.value), seed: Number(seed.value) },
    }));
    box.dataset.request = JSON.stringify({ rod: p, paths: Number(paths.value), seed: Number(seed.value) });
    const started = performance.now();
    api.run(jobs, (msg) => {
      const r = rows[msg.key];
      if (msg.error) {
        r.paths.textContent = msg.error;
        return;
      }
      const j = JSON.parse(msg.json);
      r.json = j;
      QUANTITIES.forEach(([q], i) => setCell(r.cells[i], msg.key, q, j[q], j.paths, exact[i]));
      r.paths.textContent = j.paths.toLocaleString("en");
      r.paths.dataset.busy = String(msg.busy);
      draw();
    }, () => {
      status.textContent = `done in ${((performance.now() - started) / 1000).toFixed(1)} s (one worker, methods in turn, a block of 65 536 paths each).`;
    });
    draw();
  }
  let pending;
  const later = () => {
    clearTimeout(pending);
    pending = setTimeout(restart, 150);
  };
  for (const el of [...Object.values(s), omega, paths, seed]) el.addEventListener(el.tagName === "SELECT" ? "change" : "input", later);
  api.ready.then(restart);
}

for (const box of document.querySelectorAll('.live-widget[data-widget^="rod"]')) widget(box);
