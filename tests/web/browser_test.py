"""The browser build in a real browser: serves dist/ on 127.0.0.1, drives headless Chromium
through the DevTools protocol and checks what a student would see:

1. the first image arrives (the page's console says so, with where the viewport is);
2. a click on the viewport picks that pixel, and the sphere pane then shows its recording:
   the screenshot is not blank there;
3. an object double-clicked and dragged by its arrow moves, and Ctrl+Z brings the viewport
   back to its image before the move, pixel for pixel;
4. an OBJ (with its MTL) dropped on the page is read as a scene, and a malformed one gives
   its file and line, not a panic; a dropped .hdr lights the scene;
5. the console has no panic and no uncaught exception from start to end.

It writes the screenshots and the console to OUT (default out/web/) and prints the timings:
the time to the first image and the browser's own render times.

    python tests/web/browser_test.py [--dist dist] [--out out/web] [--chromium chromium]

Needs `websocket-client` (pip).
"""

import argparse
import base64
import functools
import http.server
import json
import os
import re
import shutil
import socket
import subprocess
import sys
import tempfile
import threading
import time
import urllib.request

import websocket

# A unit box on a floor under an emissive quad: a light, an occluder and a receiver.
DROPPED_OBJ = """mtllib dropped.mtl
o floor
usemtl white
v -4 0 -4
v 4 0 -4
v 4 0 4
v -4 0 4
f 1 3 2
f 1 4 3
o box
usemtl white
v -0.5 0.2 -0.5
v 0.5 0.2 -0.5
v 0.5 1.2 -0.5
v -0.5 1.2 -0.5
v -0.5 0.2 0.5
v 0.5 0.2 0.5
v 0.5 1.2 0.5
v -0.5 1.2 0.5
f 5 8 7 6
f 9 10 11 12
f 5 6 10 9
f 8 12 11 7
f 5 9 12 8
f 6 7 11 10
o lamp
usemtl light
v -0.7 3 -0.7
v -0.7 3 0.7
v 0.7 3 0.7
v 0.7 3 -0.7
f 13 14 15 16
"""
DROPPED_MTL = """newmtl white
Kd 0.8 0.8 0.8
newmtl light
Kd 0 0 0
Ke 10 10 10
"""
MALFORMED_OBJ = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 nine\n"


def tiny_hdr(width=8, height=4):
    """A Radiance HDR file: a sky brighter at the top, flat (uncompressed) scanlines."""
    header = f"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y {height} +X {width}\n".encode()
    pixels = bytearray()
    for y in range(height):
        for x in range(width):
            # RGBE with exponent 128 (values m / 256): bluish, brighter toward the top.
            b = 255 - 40 * y
            pixels += bytes([b // 2, b * 3 // 4, b, 128])
    return header + bytes(pixels)


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def serve(directory):
    """A static server of `directory` on 127.0.0.1 in a thread; returns its port."""
    class Quiet(http.server.SimpleHTTPRequestHandler):
        extensions_map = {**http.server.SimpleHTTPRequestHandler.extensions_map,
                          ".wasm": "application/wasm"}

        def log_message(self, *args):
            pass

    handler = functools.partial(Quiet, directory=directory)
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    return server.server_address[1]


class Page:
    """One page over the DevTools protocol: commands, and the console as it arrives."""

    def __init__(self, ws_url):
        self.ws = websocket.create_connection(ws_url, timeout=30, suppress_origin=True)
        self.next_id = 0
        self.console = []  # (seconds since start, text)
        self.start = time.monotonic()

    def _event(self, msg):
        method, p = msg.get("method"), msg.get("params", {})
        t = time.monotonic() - self.start
        if method == "Runtime.consoleAPICalled":
            text = " ".join(str(a.get("value", a.get("description", ""))) for a in p["args"])
            self.console.append((t, f"{p['type']}: {text}"))
        elif method == "Runtime.exceptionThrown":
            d = p["exceptionDetails"]
            text = d.get("exception", {}).get("description") or d.get("text")
            self.console.append((t, f"exception: {text}"))
        elif method == "Log.entryAdded":
            e = p["entry"]
            self.console.append((t, f"log {e['level']}: {e['text']}"))

    def send(self, method, **params):
        self.next_id += 1
        self.ws.settimeout(60)
        self.ws.send(json.dumps({"id": self.next_id, "method": method, "params": params}))
        while True:
            msg = json.loads(self.ws.recv())
            if msg.get("id") == self.next_id:
                if "error" in msg:
                    raise RuntimeError(f"{method}: {msg['error']}")
                return msg.get("result", {})
            self._event(msg)

    def wait_for(self, pattern, timeout, after=0):
        """The first console line (from index `after`) matching `pattern`."""
        deadline = time.monotonic() + timeout
        while True:
            for i, (_, line) in enumerate(self.console[after:], after):
                m = re.search(pattern, line)
                if m:
                    return i, m
            left = deadline - time.monotonic()
            if left <= 0:
                raise TimeoutError(f"no console line matching {pattern!r} in {timeout} s")
            self.ws.settimeout(min(left, 1.0))
            try:
                self._event(json.loads(self.ws.recv()))
            except websocket.WebSocketTimeoutException:
                pass

    def evaluate(self, expression):
        r = self.send("Runtime.evaluate", expression=expression, awaitPromise=True,
                      returnByValue=True)
        if "exceptionDetails" in r:
            raise RuntimeError(f"script failed: {r['exceptionDetails']}")
        return r["result"].get("value")

    def screenshot(self, path):
        data = self.send("Page.captureScreenshot", format="png")["data"]
        with open(path, "wb") as f:
            f.write(base64.b64decode(data))
        return data

    def click(self, x, y):
        for kind in ["mouseMoved", "mousePressed", "mouseReleased"]:
            self.send("Input.dispatchMouseEvent", type=kind, x=x, y=y, button="left",
                      clickCount=1)
            time.sleep(0.05)

    def drag(self, start, end, steps=12):
        x0, y0 = start
        x1, y1 = end
        self.send("Input.dispatchMouseEvent", type="mouseMoved", x=x0, y=y0)
        self.send("Input.dispatchMouseEvent", type="mousePressed", x=x0, y=y0, button="left",
                  clickCount=1)
        for k in range(1, steps + 1):
            t = k / steps
            time.sleep(0.05)
            self.send("Input.dispatchMouseEvent", type="mouseMoved", x=x0 + t * (x1 - x0),
                      y=y0 + t * (y1 - y0), button="left", buttons=1)
        self.send("Input.dispatchMouseEvent", type="mouseReleased", x=x1, y=y1, button="left",
                  clickCount=1)

    def double_click(self, x, y):
        self.send("Input.dispatchMouseEvent", type="mouseMoved", x=x, y=y)
        for count in [1, 2]:
            for kind in ["mousePressed", "mouseReleased"]:
                self.send("Input.dispatchMouseEvent", type=kind, x=x, y=y, button="left",
                          clickCount=count)

    def ctrl_key(self, key, code, vk):
        for kind in ["rawKeyDown", "keyUp"]:
            self.send("Input.dispatchKeyEvent", type=kind, modifiers=2, key=key, code=code,
                      windowsVirtualKeyCode=vk)

    def drop(self, files):
        """Drops `files` ({name: text or bytes}) on the canvas, as a user's drag and drop
        does."""
        encoded = {n: base64.b64encode(c if isinstance(c, bytes) else c.encode()).decode()
                   for n, c in files.items()}
        js = json.dumps(encoded)
        return self.evaluate(f"""(() => {{
            const dt = new DataTransfer();
            for (const [name, b64] of Object.entries({js})) {{
                const bytes = Uint8Array.from(atob(b64), (c) => c.charCodeAt(0));
                dt.items.add(new File([bytes], name));
            }}
            const canvas = document.getElementById("penumbra");
            for (const type of ["dragenter", "dragover", "drop"])
                canvas.dispatchEvent(new DragEvent(type, {{dataTransfer: dt, bubbles: true,
                                                           cancelable: true}}));
            return dt.files.length;
        }})()""")


def spread_in(page, png_b64, rect):
    """The standard deviation of the screenshot's grey values inside rect (x, y, w, h)."""
    x, y, w, h = rect
    return page.evaluate(f"""(async () => {{
        const img = new Image();
        img.src = "data:image/png;base64,{png_b64}";
        await img.decode();
        const c = new OffscreenCanvas(img.width, img.height);
        const g = c.getContext("2d");
        g.drawImage(img, 0, 0);
        const d = g.getImageData({x}, {y}, {w}, {h}).data;
        let n = 0, s = 0, s2 = 0;
        for (let i = 0; i < d.length; i += 4) {{
            const v = (d[i] + d[i + 1] + d[i + 2]) / 3;
            n++; s += v; s2 += v * v;
        }}
        return Math.sqrt(Math.max(0, s2 / n - (s / n) ** 2));
    }})()""")


def differing_pixels(page, png_a, png_b, rect):
    """How many pixels inside rect (x, y, w, h) differ between two screenshots."""
    x, y, w, h = rect
    return page.evaluate(f"""(async () => {{
        const data = [];
        for (const src of ["{png_a}", "{png_b}"]) {{
            const img = new Image();
            img.src = "data:image/png;base64," + src;
            await img.decode();
            const c = new OffscreenCanvas(img.width, img.height);
            const g = c.getContext("2d");
            g.drawImage(img, 0, 0);
            data.push(g.getImageData({x}, {y}, {w}, {h}).data);
        }}
        let n = 0, box = [1e9, 1e9, -1, -1];
        for (let i = 0; i < data[0].length; i += 4)
            if (data[0][i] != data[1][i] || data[0][i + 1] != data[1][i + 1]
                || data[0][i + 2] != data[1][i + 2]) {{
                n++;
                const px = (i / 4) % {w} + {x}, py = Math.floor(i / 4 / {w}) + {y};
                box = [Math.min(box[0], px), Math.min(box[1], py),
                       Math.max(box[2], px), Math.max(box[3], py)];
            }}
        return [n, box];
    }})()""")


def rect_of(text):
    x, y, w, h = (float(v) for v in re.match(r"\((\S+), (\S+), (\S+)×(\S+)\)", text).groups())
    return int(x), int(y), int(w), int(h)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--dist", default="dist")
    ap.add_argument("--out", default="out/web")
    ap.add_argument("--chromium", default=shutil.which("chromium") or "chromium")
    ap.add_argument("--timeout", type=float, default=240)
    ap.add_argument("--query", default="preset=teach",
                    help="the page address's query (e.g. preset=teach&method=ratio)")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    port = serve(os.path.abspath(args.dist))
    debug_port = free_port()
    profile = tempfile.mkdtemp(prefix="penumbra-chromium-")
    browser = subprocess.Popen(
        [args.chromium, "--headless=new", "--no-sandbox", "--use-angle=swiftshader",
         "--enable-unsafe-swiftshader", "--window-size=1280,800", "--no-first-run",
         f"--remote-debugging-port={debug_port}", f"--user-data-dir={profile}",
         "about:blank"],
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    failures = []
    try:
        for _ in range(100):
            try:
                targets = json.load(urllib.request.urlopen(
                    f"http://127.0.0.1:{debug_port}/json/list", timeout=2))
                pages = [t for t in targets if t["type"] == "page"]
                if pages:
                    break
            except OSError:
                pass
            time.sleep(0.2)
        else:
            sys.exit("Chromium did not open its DevTools port")
        page = Page(pages[0]["webSocketDebuggerUrl"])
        for domain in ["Runtime", "Log", "Page"]:
            page.send(f"{domain}.enable")
        page.start = time.monotonic()
        page.send("Page.navigate", url=f"http://127.0.0.1:{port}/index.html?{args.query}")

        # 1. The first image.
        _, m = page.wait_for(r"first image after (\S+) s; viewport at (\(.*\))", args.timeout)
        first_image = time.monotonic() - page.start
        viewport = rect_of(m.group(2))
        print(f"first image {first_image:.1f} s after the page was opened "
              f"(the app's own count: {m.group(1)} s); viewport {viewport}")
        i, m = page.wait_for(r"render \d+ finished: (.*)", args.timeout)
        print(f"first render: {m.group(1)}")

        # 2. A click picks that pixel; the sphere pane shows its recording.
        vx, vy, vw, vh = viewport
        cx, cy = vx + vw * 0.42, vy + vh * 0.7
        mark = len(page.console)
        page.click(cx, cy)
        page.wait_for(r"status: picked \(", 60, after=mark)
        _, m = page.wait_for(r"recording of pixel \((\S+), (\S+)\): (\d+) stages; sphere at "
                             r"(\(.*\))", 60, after=mark)
        stages, sphere = int(m.group(3)), rect_of(m.group(4))
        time.sleep(1.0)  # the sphere pane's next frames
        shot = page.screenshot(os.path.join(args.out, "teach.png"))
        spread = spread_in(page, shot, sphere)
        print(f"clicked ({cx:.0f}, {cy:.0f}): pixel ({m.group(1)}, {m.group(2)}), {stages} "
              f"stages; sphere pane {sphere}, grey spread {spread:.1f}")
        if stages < 1:
            failures.append("the recording has no stage")
        if spread < 5:
            failures.append(f"the sphere pane looks blank (grey spread {spread:.1f})")

        # 3. Moving an object, and undoing it: the image comes back bit for bit.
        vshot = lambda: page.send("Page.captureScreenshot", format="png")["data"]
        mark = len(page.console)
        on_object = (vx + 0.70 * vw, vy + 0.63 * vh)
        page.double_click(*on_object)
        # The double-click selects the object (its handles appear); its clicks pick too.
        _, m = page.wait_for(r"status: picked \(\S+, \S+\): (.+)", 30, after=mark)
        name = m.group(1)
        _, m = page.wait_for(r"handles: the x arrow from \((\S+), (\S+)\) to \((\S+), (\S+)\)",
                             30, after=mark)
        (ax, ay, bx, by) = (float(v) for v in m.groups())
        time.sleep(0.5)
        before = vshot()
        mark = len(page.console)
        grab = (ax + 0.6 * (bx - ax), ay + 0.6 * (by - ay))
        page.drag(grab, (grab[0] + 1.5 * (bx - ax), grab[1] + 1.5 * (by - ay)))
        page.wait_for(r"render \d+ finished", args.timeout, after=mark)
        time.sleep(0.5)
        moved, _ = differing_pixels(page, before, vshot(), viewport)
        mark = len(page.console)
        page.ctrl_key("z", "KeyZ", 90)
        page.wait_for(r"status: undone", 30, after=mark)
        page.wait_for(r"render \d+ finished", args.timeout, after=mark)
        # The pointer back where it was, so that the handles' hover highlight is as it was.
        page.send("Input.dispatchMouseEvent", type="mouseMoved", x=on_object[0], y=on_object[1])
        time.sleep(0.5)
        after = vshot()
        undone, box = differing_pixels(page, before, after, viewport)
        for png, file in [(before, "before_move.png"), (after, "after_undo.png")]:
            with open(os.path.join(args.out, file), "wb") as f:
                f.write(base64.b64decode(png))
        print(f"moved {name} along x: {moved} viewport pixels changed; after undo "
              f"{undone} differ from before the move")
        if moved < 100:
            failures.append(f"dragging {name}'s arrow changed {moved} pixels only")
        if undone != 0:
            failures.append(f"after undo, {undone} viewport pixels differ from before the "
                            f"move, in {box}")

        # 4. Dropped files.
        mark = len(page.console)
        page.drop({"dropped.obj": DROPPED_OBJ, "dropped.mtl": DROPPED_MTL})
        _, m = page.wait_for(r"status: dropped\.obj: (\d+) objects", 60, after=mark)
        print(f"dropped OBJ read: {m.group(1)} objects")
        page.wait_for(r"render \d+ finished", args.timeout, after=mark)
        page.screenshot(os.path.join(args.out, "dropped.png"))
        mark = len(page.console)
        page.drop({"malformed.obj": MALFORMED_OBJ})
        _, m = page.wait_for(r"status: (malformed\.obj.*)", 60, after=mark)
        print(f"malformed OBJ: {m.group(1)}")
        if not re.search(r"malformed\.obj:\d+", m.group(1)):
            failures.append(f"the malformed OBJ's error names no line: {m.group(1)}")
        mark = len(page.console)
        page.drop({"tiny.hdr": tiny_hdr()})
        _, m = page.wait_for(r"status: (.*tiny\.hdr.*)", 60, after=mark)
        print(f"dropped HDR: {m.group(1)}")
        if not m.group(1).startswith("environment map"):
            failures.append(f"the dropped HDR was not read: {m.group(1)}")
        page.wait_for(r"render \d+ finished", args.timeout, after=mark)
        page.screenshot(os.path.join(args.out, "environment.png"))
        time.sleep(1.0)
    finally:
        console = getattr(locals().get("page"), "console", [])
        with open(os.path.join(args.out, "console.txt"), "w") as f:
            for t, line in console:
                f.write(f"{t:8.2f}  {line}\n")
        browser.terminate()
        browser.wait(timeout=10)
        shutil.rmtree(profile, ignore_errors=True)

    # 5. Nothing went wrong on the way.
    for t, line in console:
        if "panicked" in line or line.startswith("exception") or "RuntimeError" in line:
            failures.append(f"console at {t:.1f} s: {line}")
    for line in [l for _, l in console if "finished" in l]:
        print(line)
    if failures:
        print("FAILED:\n  " + "\n  ".join(failures))
        sys.exit(1)
    print(f"browser test passed ({args.out}/console.txt, teach.png, dropped.png)")


if __name__ == "__main__":
    main()
