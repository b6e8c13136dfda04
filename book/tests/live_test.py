"""The live book in a real browser (headless Chromium through selenium).

Serves the built book (book/book, with its WebAssembly package and MathJax)
on 127.0.0.1, then drives each widget: load, set a slider, wait for the
requested path count, read every estimate's data- attributes and compare
them with the command line's JSON for the same scene, seed and paths. Also:
no formula left as raw TeX, a page whose WebAssembly is blocked shows a
message, and the paths/s of one worker against the native single-thread rate.

    python3 book/tests/live_test.py GEOSENS_BINARY SCREENSHOT_DIR

Prints one line per check and closes with 'N passed, N failed'; exits 1 on a
failure. Means and standard errors agree bit for bit, or, where the
browser's libm rounds exp and log differently from the native one, within a
relative 1e-12 (counted apart in each line), with the same reliable flag.
"""
import functools
import http.server
import json
import os
import subprocess
import sys
import tempfile
import threading
import time

from selenium import webdriver
from selenium.webdriver.chrome.options import Options
from selenium.webdriver.chrome.service import Service

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BOOK = os.path.join(ROOT, "book", "book")
CLI, SHOTS = sys.argv[1], sys.argv[2]
results = []


def check(name, ok, detail=""):
    results.append(ok)
    print(f"{'PASS' if ok else 'FAIL'} {name}{': ' + detail if detail else ''}", flush=True)


class Handler(http.server.SimpleHTTPRequestHandler):
    """The book's files, quietly; with `block`, without its WebAssembly package."""

    block = False

    def log_message(self, *args):
        pass

    def do_GET(self):
        if self.block and "/live/pkg/" in self.path:
            self.send_error(404)
            return
        super().do_GET()


class Blocked(Handler):
    block = True


def serve(handler=Handler):
    handler = functools.partial(handler, directory=BOOK)
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    return server, f"http://127.0.0.1:{server.server_address[1]}"


def browser():
    o = Options()
    for a in ("--headless=new --no-sandbox --disable-gpu --disable-background-networking "
              "--disable-component-update --disable-sync --no-first-run").split():
        o.add_argument(a)
    o.add_argument("--user-data-dir=" + tempfile.mkdtemp(prefix="geosens-chromium-"))
    o.add_argument("--window-size=1280,1800")
    o.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    return webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=o)


def wait(d, js, timeout=120, what="condition"):
    end = time.time() + timeout
    while time.time() < end:
        v = d.execute_script(js)
        if v:
            return v
        time.sleep(0.2)
    raise TimeoutError(what)


def estimates(d, box_sel, which=":not([data-x])"):
    """The displayed estimates: at the probe (default), or `which` another
    selector suffix (`[data-x]`: the rod's points on the curves)."""
    return d.execute_script(
        """return [...document.querySelectorAll(arguments[0] + ' .live-estimate' + arguments[1])].map(e => ({
            method: e.dataset.method, quantity: e.dataset.quantity, mean: e.dataset.mean,
            stderr: e.dataset.stderr, paths: e.dataset.paths, reliable: e.dataset.reliable,
            x: e.dataset.x, omega: e.dataset.omega}))""",
        box_sel, which)


def shot(d, box_sel, path):
    """A screenshot of the widget, scrolled clear of the book's top bar."""
    el = d.find_element("css selector", box_sel)
    d.execute_script("arguments[0].scrollIntoView(); window.scrollBy(0, -60)", el)
    time.sleep(0.3)
    el.screenshot(path)


def settle(d, box_sel, paths, timeout=300):
    """After inputs changed: the widget restarted (150 ms later) and ran."""
    time.sleep(0.6)
    wait_paths(d, box_sel, paths, timeout)


def wait_paths(d, box_sel, paths, timeout=300):
    js = f"""const es = [...document.querySelectorAll('{box_sel} .live-estimate:not([data-x])')];
             return es.length > 0 && es.every(e => e.dataset.paths === '{paths}')
                    && document.querySelector('{box_sel}').dataset.running === 'false';"""
    wait(d, js, timeout, f"{box_sel} at {paths} paths")


def set_input(d, box_sel, name, value):
    d.execute_script(
        """const el = document.querySelector(arguments[0] + ' [name=' + arguments[1] + ']');
           el.value = arguments[2];
           el.dispatchEvent(new Event(el.tagName === 'SELECT' ? 'change' : 'input'));""",
        box_sel, name, str(value))


def cli(args):
    return json.loads(subprocess.run([CLI, *args, "--threads", "1", "--json"], check=True,
                                     capture_output=True, text=True).stdout)


def lookup(line, quantity):
    if ":" in quantity:
        kind, name = quantity.split(":")
        return (line[kind] or {}).get(name)
    return line[quantity]


def compare(name, shown, cli_lines):
    """Every displayed estimate against the CLI's line of its method."""
    bits, close, rounded, far = 0, 0, 0, []
    for e in shown:
        ref = lookup(cli_lines[e["method"]], e["quantity"])
        if ref is None:
            if e["mean"] != "":
                far.append((e, None))
            continue
        m, s = float(e["mean"]), float(e["stderr"])
        rel = (e["reliable"] == "true") == ref["reliable"]
        if m == ref["mean"] and s == ref["stderr"] and rel:
            bits += 1
        elif m == ref["mean"] and abs(s - ref["stderr"]) <= 1e-12 * abs(ref["stderr"]) and rel:
            close += 1
        elif (abs(m - ref["mean"]) <= 1e-12 * abs(ref["mean"])
              and abs(s - ref["stderr"]) <= 1e-12 * abs(ref["stderr"]) and rel):
            rounded += 1
        else:
            far.append((e, ref))
    check(name, not far and bits + close + rounded > 0,
          f"{bits} estimates bit-identical to the CLI, {close} with the mean identical and the "
          f"stderr within 1e-12 relative, {rounded} with both within 1e-12 relative (the "
          f"browser's exp and log round differently)" + (f"; differing: {far[:3]}" if far else ""))


def rod_cli(rod, method, paths, seed):
    return cli(["rod", "--method", method, "--ks", repr(rod["ks"]), "--ke", repr(rod["ke"]),
                "--length", repr(rod["length"]), "--x", repr(rod["x"]), "--omega", repr(rod["omega"]),
                *(["--paths", str(paths), "--seed", str(seed)] if method != "exact" else [])])


def rod_widget(d, url, shots):
    d.get(url + "/rod.html")
    box = '.live-widget[data-widget="rod"]'
    wait(d, f"return document.querySelector('{box}').dataset.state === 'ready'", 60, "rod ready")
    check("rod widget loads its WebAssembly", True)
    set_input(d, box, "paths", 262144)
    set_input(d, box, "x", 0.3)
    settle(d, box, 262144)
    shown = estimates(d, box)
    p = json.loads(d.execute_script(f"return document.querySelector('{box}').dataset.request"))
    rod = p["rod"]
    lines = {m: rod_cli(rod, m, p["paths"], p["seed"]) for m in {e["method"] for e in shown}}
    compare(f"rod widget at x = {rod['x']} matches `geosens rod --json`", shown, lines)
    shot(d, box, os.path.join(shots, "rod.png"))
    rod_curves(d, box, shots)


def rod_curves(d, box, shots):
    """Figs. 5/6: a slider move redraws the exact curves (the library's
    Bellman–Wing values, as `geosens rod --method exact` prints them) and
    reruns every method at nine points per direction."""
    curves = "return document.querySelector(arguments[0] + ' canvas').dataset.curves"
    before = json.loads(d.execute_script(curves, box))
    set_input(d, box, "ks", 0.9)
    set_input(d, box, "length", 1.5)
    settle(d, box, 262144)
    after = json.loads(d.execute_script(curves, box))
    check("rod: a slider move changes the exact curves",
          after["ks"] == 0.9 and after["length"] == 1.5 and after["right"] != before["right"],
          f"I(π̃, +1) {before['right']['intensity'][-1]:.6f} → {after['right']['intensity'][-1]:.6f}")
    worst = 0.0
    for i in (0, 50, 137, 200):
        for side, omega in (("right", 1.0), ("left", -1.0)):
            rod = {"ks": 0.9, "ke": after["ke"], "length": 1.5, "x": after["x"][i], "omega": omega}
            ref = rod_cli(rod, "exact", 0, 0)
            for q in ("intensity", "sensitivity"):
                a, b = after[side][q][i], ref[q]["mean"]
                worst = max(worst, abs(a - b) / max(abs(b), 1e-300) if a != b else 0.0)
    check("rod: the curves are `geosens rod --method exact` along x", worst <= 1e-12,
          f"largest relative difference {worst:.1e} at 8 points")
    points = estimates(d, box, "[data-x]")
    p = json.loads(d.execute_script(f"return document.querySelector('{box}').dataset.request"))
    n = p["point_paths"]
    done = [e for e in points if e["paths"] == str(n)]
    methods = {e["method"] for e in points}
    # Finite differences cannot shorten the rod past a probe at its end.
    refused = d.execute_script(
        f"return [...document.querySelectorAll('{box} td[data-error]')].map(e => +e.dataset.x)")
    check("rod: every method estimated at 9 points in both directions",
          len(done) == len(points) and len(points) + len(refused) == 9 * 2 * len(methods) * 2
          and all(x == 1.5 for x in refused),
          f"{len(done)} cells at {n} paths, methods {sorted(methods)}; {len(refused)} refused "
          f"(fd at x = π̃)")
    chosen = [e for e in points if e["method"] in ("expectation", "rendering")
              and (e["x"], e["omega"]) in {(repr(after["x"][100]), "1"), (repr(after["x"][175]), "-1")}]
    for (x, omega) in {(e["x"], e["omega"]) for e in chosen}:
        here = [e for e in chosen if (e["x"], e["omega"]) == (x, omega)]
        rod = {"ks": 0.9, "ke": after["ke"], "length": 1.5, "x": float(x), "omega": float(omega)}
        lines = {m: rod_cli(rod, m, n, p["seed"]) for m in {e["method"] for e in here}}
        compare(f"rod: the curve points at x = {x}, ω = {omega} match `geosens rod --json`", here, lines)
    shot(d, box, os.path.join(shots, "rod-curves.png"))


def flat_cli(scene_text, method, paths, seed, threads="1"):
    with tempfile.NamedTemporaryFile("w", suffix=".json", delete=False) as f:
        f.write(scene_text)
    try:
        return json.loads(subprocess.run(
            [CLI, "flat", "--scene", f.name, "--method", method, "--paths", str(paths), "--seed", str(seed),
             "--threads", threads, "--json"], check=True, capture_output=True, text=True).stdout)
    finally:
        os.unlink(f.name)


def closed_form(d, box):
    return d.execute_script(
        f"return [...document.querySelectorAll('{box} .live-exact')].map(e => [e.dataset.quantity, +e.dataset.exact])")


def flat_widget(d, url, shots):
    d.get(url + "/flatland.html")
    box = '.live-widget[data-widget="flat"]'
    wait(d, f"return document.querySelector('{box}').dataset.state === 'ready'", 60, "flat ready")
    set_input(d, box, "occluder_rotate", 12)
    settle(d, box, 262144)
    shown = estimates(d, box)
    scene = d.execute_script(f"return document.querySelector('{box}').dataset.scene")
    lines = {m: flat_cli(scene, m, 262144, 1) for m in {e["method"] for e in shown}}
    compare("flatland occluder turned 12° matches `geosens flat --json`", shown, lines)
    exact = [x for _, x in closed_form(d, box)]
    mean = [float(e["mean"]) for e in shown if e["method"] == "expectation"]
    err = [float(e["stderr"]) for e in shown if e["method"] == "expectation"]
    z = max(abs(m - x) / s for m, x, s in zip(mean, exact, err))
    check("flatland expectation within 5σ of the closed form", z < 5, f"largest |z| = {z:.2f}")
    shot(d, box, os.path.join(shots, "flat.png"))
    drawn_paths(d, box)
    flat_lamp(d, box, shots)


def drawn_paths(d, box):
    """The lines drawn are the estimator's own first paths: the widget's
    vertices are what geosens-web's sampled_paths records for the scene,
    method and seed, every walk from the sensor starts at the sensor, and
    the weights of the first 4096 paths sampled with the recorder on (one
    chunk) give the command line's estimates for --paths 4096."""
    drawn = json.loads(d.execute_script(f"return document.querySelector('{box} canvas').dataset.drawn"))
    request, v = drawn["request"], drawn["vertices"]
    sensor = request["flat"]["sensor"]["point"]
    starts = [v[i + 2:i + 4] for i in range(0, len(v), 5) if i == 0 or v[i:i + 2] != v[i - 5:i - 3]]
    main = [v[i + 2:i + 4] for i in range(0, len(v), 5)
            if v[i + 1] == 0 and (i == 0 or v[i] != v[i - 5])]
    check("flatland: the drawn paths start at the sensor",
          len(main) == drawn["n"] and all(p == sensor for p in main),
          f"{len(main)} paths of {request['method']}, {len(starts)} walks, {len(v) // 5} vertices")
    d.set_script_timeout(300)
    got = d.execute_async_script(CALL, "sampled_paths", [json.dumps(request), 4096])
    got = json.loads(got["value"])
    check("flatland: the drawn vertices are the first of sampled_paths' recording",
          got["vertices"][:len(v)] == v, f"{len(v) // 5} vertices compared")
    line = flat_cli(json.dumps(request["flat"]), request["method"], 4096, request["seed"])
    w = got["weights"]
    means = [sum(p[k] for p in w) / len(w) for k in range(len(w[0]))]
    # Summed in another order than the runner's: rounding relative to the weights' size.
    sizes = [sum(abs(p[k]) for p in w) / len(w) for k in range(len(w[0]))]
    refs = [line["intensity"]["mean"]] + [line["sensitivity"][q["name"]]["mean"]
                                          for q in request["flat"]["parameters"]]
    worst = max(abs(a - b) / max(m, 1e-300) for a, b, m in zip(means, refs, sizes))
    check("flatland: the recorded paths' weights give the CLI's estimates for --paths 4096",
          len(w) == 4096 and worst < 1e-12,
          f"{len(refs)} quantities, largest difference {worst:.1e} of the mean |weight|")


def flat_lamp(d, box, shots):
    """Turning and scaling the lamp moves the closed form of E, to where
    the command line's estimate of the same scene is (the CLI prints no
    flatland closed form: 2²⁰ paths of expectation, every quantity within
    4σ)."""
    before = dict(closed_form(d, box))
    set_input(d, box, "lamp_rotate", 20)
    set_input(d, box, "lamp_scale", 0.7)
    settle(d, box, 262144)
    after = dict(closed_form(d, box))
    scene = d.execute_script(f"return document.querySelector('{box}').dataset.scene")
    lamp = json.loads(scene)["shapes"][0]["vertices"]
    line = flat_cli(scene, "expectation", 1 << 20, 5, threads="0")
    zs, moved = [], []
    for q, x in after.items():
        e = lookup(line, q)
        zs.append(abs(e["mean"] - x) / e["stderr"])
        moved.append(abs(before[q] - x) / e["stderr"])
    check("flatland: the lamp turned 20° and scaled 0.7, the closed form agrees with the CLI",
          max(zs) < 4 and moved[0] > 10 and abs(lamp[1][1] - lamp[0][1]) > 0.4,
          f"E {before['intensity']:.6f} → {after['intensity']:.6f} ({moved[0]:.0f}σ); largest |z| "
          f"against `geosens flat` {max(zs):.2f} (the occluder's ∂E/∂π stay: its shadow edge "
          f"still falls on the lamp)")
    shown = estimates(d, box)
    lines = {m: flat_cli(scene, m, 262144, 1) for m in {e["method"] for e in shown}}
    compare("flatland with the lamp turned and scaled matches `geosens flat --json`", shown, lines)
    shot(d, box, os.path.join(shots, "flat-lamp.png"))


def flags(shown):
    return {f"{e['method']} {e['quantity']}": e["reliable"] for e in shown if e["mean"] != ""}


def fail_widget(d, url, shots):
    """The flag trips where the book says: the thin rod in runs of 4096
    paths (expectation's ∂I/∂π̃, not rendering's), and the thick rod looking
    left just short of the moving end; each time as the CLI's JSON says."""
    d.get(url + "/comparing.html")
    box = '.live-widget[data-widget="rod-fail"]'
    wait(d, f"return document.querySelector('{box}').dataset.state === 'ready'", 60, "fail ready")
    cases = [("thin rod, 4096 paths, x = 0.98 π̃, ω = +1", {}),
             ("thick rod, 4096 paths, x = 0.9995 π̃, ω = −1",
              {"ke": 3, "ks": 2.1, "length": 2, "omega": -1, "x": 0.9995})]
    for i, (name, inputs) in enumerate(cases):
        for k, v in inputs.items():
            set_input(d, box, k, v)
        settle(d, box, 4096)
        shown = estimates(d, box)
        f = flags(shown)
        p = json.loads(d.execute_script(f"return document.querySelector('{box}').dataset.request"))
        lines = {m: rod_cli(p["rod"], m, p["paths"], p["seed"]) for m in {e["method"] for e in shown}}
        check(f"where methods fail, {name}: expectation's ∂I/∂π̃ flagged, rendering's not",
              f["expectation sensitivity"] == "false" and f["rendering sensitivity"] == "true",
              json.dumps(f))
        compare(f"where methods fail, {name}: the flags and numbers are the CLI's", shown, lines)
        shot(d, box, os.path.join(shots, f"fail-{i + 1}.png"))
    points = [e for e in estimates(d, box, "[data-x]") if e["mean"] != ""]
    check("where methods fail: the curve points carry their flags",
          {e["reliable"] for e in points} == {"true", "false"},
          f"{sum(e['reliable'] == 'false' for e in points)} of {len(points)} flagged")
    flat_fail(d, url, shots)


def flat_fail(d, url, shots):
    """Flatland: the sensor 10⁻⁵ from the moving edge of its absorbing box;
    the error bars grow tenfold and more from d = 0.32, the VOV flags
    rendering and transport, and the numbers are the CLI's."""
    box = '.live-widget[data-widget="flat-fail"]'
    wait(d, f"return document.querySelector('{box}').dataset.state === 'ready'", 60, "flat-fail ready")
    wait_paths(d, box, 65536)
    far = {e["method"]: float(e["stderr"]) for e in estimates(d, box) if "box_tx" in e["quantity"]}
    set_input(d, box, "log_d", -5)
    settle(d, box, 65536)
    shown = estimates(d, box)
    near = {e["method"]: float(e["stderr"]) for e in shown if "box_tx" in e["quantity"]}
    f = flags(shown)
    grew = min(near[m] / far[m] for m in ("expectation", "rendering", "transport"))
    check("flatland, sensor 1e-5 from the moving edge: the error bars grow, the flag trips",
          grew > 10 and "false" in [f[f"{m} sensitivity:box_tx"] for m in ("rendering", "transport")],
          f"stderr ×{grew:.0f} at least; {json.dumps(f)}")
    scene = d.execute_script(f"return document.querySelector('{box}').dataset.scene")
    lines = {m: flat_cli(scene, m, 65536, 1) for m in {e["method"] for e in shown}}
    compare("flatland, sensor near the moving edge: the CLI's numbers and flags", shown, lines)
    shot(d, box, os.path.join(shots, "flat-fail.png"))


def math(d, url):
    for page in ("rod.html", "expectation.html", "flatland.html", "introduction.html"):
        d.get(f"{url}/{page}")
        n = wait(d, "return document.querySelectorAll('mjx-container').length", 60, "MathJax")
        raw = d.execute_script(
            """const main = document.querySelector('main').cloneNode(true);
               main.querySelectorAll('pre, code, mjx-container').forEach(e => e.remove());
               const t = main.innerText;
               return ['\\\\(', '\\\\[', '\\\\frac', '\\\\partial'].filter(s => t.includes(s));""")
        check(f"{page}: formulas typeset offline", n > 0 and not raw, f"{n} formulas, raw TeX: {raw}")


def broken_wasm(d, shots):
    server, url = serve(Blocked)
    d.get(url + "/rod.html")
    box = '.live-widget[data-widget="rod"]'
    msg = wait(d, f"const e = document.querySelector('{box} .live-error'); return e && e.textContent", 40,
               "error message")
    check("a page whose WebAssembly does not load says so", "cannot run" in msg, msg[:90])
    shot(d, box, os.path.join(shots, "no-wasm.png"))
    server.shutdown()


BENCH = """
const [request, done] = [arguments[0], arguments[arguments.length - 1]];
const w = new Worker(new URL('live/worker.js', location.href), {type: 'module'});
let last = null;
w.onmessage = (ev) => {
  const m = ev.data;
  if (m.type === 'ready') w.postMessage({type: 'run', id: 1, jobs: [{key: 'b', request}]});
  else if (m.type === 'progress') last = m;
  else if (m.type === 'done') { w.terminate(); done(last); }
  else if (m.type === 'error') done({error: m.message});
};
"""


CALL = """
const [fn, args, done] = [arguments[0], arguments[1], arguments[arguments.length - 1]];
const w = new Worker(new URL('live/worker.js', location.href), {type: 'module'});
w.onmessage = (ev) => {
  const m = ev.data;
  if (m.type === 'ready') w.postMessage({type: 'call', id: 1, fn, args});
  else if (m.type === 'result') { w.terminate(); done(m); }
  else if (m.type === 'error') done({error: m.message});
};
"""


def speed(d, url, scene_json):
    d.get(url + "/rod.html")
    d.set_script_timeout(600)
    # The page's widgets start on load, each in a worker of its own: the
    # bench waits until they are idle, or it shares the cores with them.
    wait(d, """const bs = [...document.querySelectorAll('.live-widget')];
               return bs.length > 0 && bs.every(b => b.dataset.running === 'false');""",
         600, "the page's widgets idle")
    rod = {"ks": 0.5, "ke": 1.0, "length": 2.0, "x": 0.7, "omega": 1.0}
    cases = [
        ("rod", {"rod": rod, "method": "expectation", "paths": 8_000_000, "seed": 1},
         ["rod", "--method", "expectation", "--ks", "0.5", "--ke", "1", "--length", "2", "--x", "0.7",
          "--omega", "1", "--paths", "8000000", "--seed", "1"]),
        ("flatland occluder", {"flat": scene_json, "method": "expectation", "paths": 2_000_000, "seed": 1},
         ["flat", "--scene", os.path.join(ROOT, "scenes", "occluder.toml"), "--method", "expectation",
          "--paths", "2000000", "--seed", "1"]),
    ]
    for name, request, args in cases:
        native = min((cli(args) for _ in range(3)), key=lambda r: r["seconds"])
        web = d.execute_async_script(BENCH, request)
        line = json.loads(web["json"])
        rate_web = line["paths"] / web["busy"]
        rate_native = native["paths"] / native["seconds"]
        ratio = rate_web / rate_native
        check(f"{name}: one worker's paths/s at least half the native single thread's", ratio >= 0.5,
              f"browser {rate_web:.3g} paths/s, native {rate_native:.3g} paths/s, ratio {ratio:.2f}")
        line["seconds"], native["seconds"] = 0, 0
        same = line == native
        if not same:
            q = "intensity"
            same = line[q]["mean"] == native[q]["mean"]
        check(f"{name}: {request['paths']} paths in the browser give the CLI's JSON",
              same, "bit-identical" if line == native else "means identical, a stderr differs in its last bits")


def main():
    os.makedirs(SHOTS, exist_ok=True)
    server, url = serve()
    import tomllib
    with open(os.path.join(ROOT, "scenes", "occluder.toml"), "rb") as f:
        scene = tomllib.load(f)
    d = browser()
    print(f"serving {BOOK} on {url}; Chromium {d.capabilities.get('browserVersion')}")
    try:
        for step in (lambda: rod_widget(d, url, SHOTS), lambda: flat_widget(d, url, SHOTS),
                     lambda: fail_widget(d, url, SHOTS), lambda: math(d, url),
                     lambda: speed(d, url, scene), lambda: broken_wasm(d, SHOTS)):
            try:
                step()
            except Exception as e:  # a step that fails still lets the others run
                check(f"step raised {type(e).__name__}", False, str(e)[:300])
    finally:
        d.quit()
        server.shutdown()
    print(f"screenshots in {SHOTS}")
    print(f"{sum(results)} passed, {len(results) - sum(results)} failed")
    sys.exit(0 if all(results) else 1)


if __name__ == "__main__":
    main()
