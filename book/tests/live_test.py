"""The live book in a real browser (headless Chromium through selenium).

Serves the built book (book/book, with its WebAssembly package and MathJax)
on 127.0.0.1, then drives each widget: load, set a slider, wait for the
requested path count, read every estimate's data- attributes and compare
them with the command line's JSON for the same scene, seed and paths. Also:
no formula left as raw TeX, a page whose WebAssembly is blocked shows a
message, and the paths/s of one worker against the native single-thread rate.

    python3 book/tests/live_test.py GEOSENS_BINARY SCREENSHOT_DIR

Prints one line per check and closes with 'N passed, N failed'; exits 1 on a
failure. Means must agree bit for bit; a standard error may differ in its
last bits (the browser's libm rounds some functions differently): within a
relative 1e-12, reported.
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


def estimates(d, box_sel):
    return d.execute_script(
        """return [...document.querySelectorAll(arguments[0] + ' .live-estimate')].map(e => ({
            method: e.dataset.method, quantity: e.dataset.quantity, mean: e.dataset.mean,
            stderr: e.dataset.stderr, paths: e.dataset.paths, reliable: e.dataset.reliable}))""",
        box_sel)


def wait_paths(d, box_sel, paths, timeout=300):
    js = f"""const es = [...document.querySelectorAll('{box_sel} .live-estimate')];
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
    bits, close, far = 0, 0, []
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
        else:
            far.append((e, ref))
    check(name, not far and bits + close > 0,
          f"{bits} estimates bit-identical to the CLI, {close} with the mean identical and the "
          f"stderr within 1e-12 relative" + (f"; differing: {far[:3]}" if far else ""))


def rod_widget(d, url, shots):
    d.get(url + "/rod.html")
    box = '.live-widget[data-widget="rod"]'
    wait(d, f"return document.querySelector('{box}').dataset.state === 'ready'", 60, "rod ready")
    check("rod widget loads its WebAssembly", True)
    set_input(d, box, "paths", 262144)
    set_input(d, box, "x", 0.3)
    time.sleep(0.5)
    wait_paths(d, box, 262144)
    shown = estimates(d, box)
    p = json.loads(d.execute_script(f"return document.querySelector('{box}').dataset.request"))
    rod = p["rod"]
    lines = {m: cli(["rod", "--method", m, "--ks", repr(rod["ks"]), "--ke", repr(rod["ke"]),
                     "--length", repr(rod["length"]), "--x", repr(rod["x"]), "--omega",
                     repr(rod["omega"]), "--paths", str(p["paths"]), "--seed", str(p["seed"])])
             for m in {e["method"] for e in shown}}
    compare(f"rod widget at x = {rod['x']} matches `geosens rod --json`", shown, lines)
    el = d.find_element("css selector", box)
    d.execute_script("arguments[0].scrollIntoView()", el)
    el.screenshot(os.path.join(shots, "rod.png"))


def flat_widget(d, url, shots):
    d.get(url + "/flatland.html")
    box = '.live-widget[data-widget="flat"]'
    wait(d, f"return document.querySelector('{box}').dataset.state === 'ready'", 60, "flat ready")
    set_input(d, box, "rotate", 12)
    time.sleep(0.5)
    wait_paths(d, box, 262144)
    shown = estimates(d, box)
    scene = d.execute_script(f"return document.querySelector('{box}').dataset.scene")
    with tempfile.NamedTemporaryFile("w", suffix=".json", delete=False) as f:
        f.write(scene)
    lines = {m: cli(["flat", "--scene", f.name, "--method", m, "--paths", "262144", "--seed", "1"])
             for m in {e["method"] for e in shown}}
    os.unlink(f.name)
    compare("flatland occluder turned 12° matches `geosens flat --json`", shown, lines)
    exact = d.execute_script(f"return [...document.querySelectorAll('{box} .live-exact')].map(e => +e.dataset.exact)")
    mean = [float(e["mean"]) for e in shown if e["method"] == "expectation"]
    err = [float(e["stderr"]) for e in shown if e["method"] == "expectation"]
    z = max(abs(m - x) / s for m, x, s in zip(mean, exact, err))
    check("flatland expectation within 5σ of the closed form", z < 5, f"largest |z| = {z:.2f}")
    el = d.find_element("css selector", box)
    d.execute_script("arguments[0].scrollIntoView()", el)
    el.screenshot(os.path.join(shots, "flat.png"))


def fail_widget(d, url, shots):
    d.get(url + "/comparing.html")
    box = '.live-widget[data-widget="rod-fail"]'
    wait(d, f"return document.querySelector('{box}').dataset.state === 'ready'", 60, "fail ready")
    set_input(d, box, "x", 0.995)
    time.sleep(0.5)
    wait_paths(d, box, 262144)
    shown = [e for e in estimates(d, box) if e["mean"] != ""]
    flags = {e["method"] + " " + e["quantity"]: e["reliable"] for e in shown}
    check("where-methods-fail widget shows a reliable flag per estimate",
          all(v in ("true", "false") for v in flags.values()) and len(flags) >= 6, json.dumps(flags))
    el = d.find_element("css selector", box)
    d.execute_script("arguments[0].scrollIntoView()", el)
    el.screenshot(os.path.join(shots, "fail.png"))


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
    el = d.find_element("css selector", box)
    d.execute_script("arguments[0].scrollIntoView()", el)
    el.screenshot(os.path.join(shots, "no-wasm.png"))
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


def speed(d, url, scene_json):
    d.get(url + "/rod.html")
    d.set_script_timeout(600)
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
