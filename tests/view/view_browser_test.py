#!/usr/bin/python3
"""frep view in headless Chromium: the page is served, the model drawn, an edit shows up, a
syntax error shows frep's own file:line:column message, and a save interrupts the job in progress.

Drives Chromium over the DevTools protocol (python3-websocket) and reads its screenshots with
PIL. The sphere's picture is checked against its exact silhouette under the page's camera
(perspective, fov 35 degrees, fitted to the -b box), the box's against the sphere's.

usage: view_browser_test.py FREP [SCREENSHOT_DIR]   (ctest view_browser; exit 0 = pass)"""
import base64
import io
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import time
import urllib.error
import urllib.request

import websocket
from PIL import Image

FREP = os.path.abspath(sys.argv[1])
SHOTS = sys.argv[2] if len(sys.argv) > 2 else None
BACKGROUND = (0x1e, 0x22, 0x28)  # app.js setClearColor
failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what, flush=True)
    if not ok:
        failures.append(what)


SPHERE = "my_model(x[3], a[1])\n{\n  my_model = 1 - x[1]^2 - x[2]^2 - x[3]^2;\n}\n"
BOX = "my_model(x[3], a[1])\n{\n  array c[3];\n  c = [-1.6, -1.6, -1.6];\n  my_model = hfBlock(x, c, 3.2, 3.2, 3.2);\n}\n"
BROKEN = "my_model(x[3], a[1])\n{\n  my_model = 1 - x[1]^2 - * x[2]^2;\n}\n"
# Slow on purpose (4000 sines at every point; about 25 s at --res 40 on 2 workers): the save
# after it must interrupt it.
SLOW = ("my_model(x[3], a[1])\n{\n  t = 0;\n  i = 0;\n  while (i < 4000) loop\n"
        "    t = t + 0.000001 * sin(x[1] * i + x[2]);\n    i = i + 1;\n  endloop;\n"
        "  my_model = 1 - x[1]^2 - x[2]^2 - x[3]^2 + t;\n}\n")


def save(path, text):
    """Writes the model as an editor does: a new file renamed over the old one."""
    with open(path + ".tmp", "w") as f:
        f.write(text)
    os.replace(path + ".tmp", path)


class Browser:
    """One headless Chromium page driven over the DevTools protocol."""

    def __init__(self, profile):
        self.proc = subprocess.Popen(
            ["chromium", "--headless=new", "--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
             "--window-size=1000,640", "--hide-scrollbars", "--remote-debugging-port=0", "--user-data-dir=" + profile,
             "--no-first-run", "--remote-allow-origins=*", "about:blank"],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        port_file = os.path.join(profile, "DevToolsActivePort")
        deadline = time.time() + 40  # a first start under a loaded machine
        while not os.path.exists(port_file) or not open(port_file).read().strip():
            if time.time() > deadline:
                raise RuntimeError("chromium did not start its DevTools server")
            time.sleep(0.1)
        port = open(port_file).read().split()[0]
        targets = json.load(urllib.request.urlopen("http://127.0.0.1:%s/json/list" % port))
        page = next(t for t in targets if t["type"] == "page")
        self.ws = websocket.create_connection(page["webSocketDebuggerUrl"], timeout=30)
        self.next_id = 0

    def call(self, method, **params):
        self.next_id += 1
        self.ws.send(json.dumps({"id": self.next_id, "method": method, "params": params}))
        while True:
            msg = json.loads(self.ws.recv())
            if msg.get("id") == self.next_id:
                if "error" in msg:
                    raise RuntimeError("%s: %s" % (method, msg["error"]))
                return msg["result"]

    def eval(self, expr):
        r = self.call("Runtime.evaluate", expression=expr, returnByValue=True)
        return r["result"].get("value")

    def wait(self, expr, seconds, what):
        deadline = time.time() + seconds
        while time.time() < deadline:
            if self.eval(expr):
                return True
            time.sleep(0.1)
        check(False, "%s within %d s (page: status %s, generation %s, drawn %s)" % (
            what, seconds, self.eval("document.body.dataset.status"), self.eval("document.body.dataset.generation"),
            self.eval("document.body.dataset.drawn")))
        return False

    def screenshot(self, name):
        png = base64.b64decode(self.call("Page.captureScreenshot", format="png")["data"])
        if SHOTS:
            os.makedirs(SHOTS, exist_ok=True)
            with open(os.path.join(SHOTS, name), "wb") as f:
                f.write(png)
        return Image.open(io.BytesIO(png)).convert("RGB")

    def close(self):
        self.ws.close()
        self.proc.terminate()
        self.proc.wait(10)


def is_model(p):  # the lit surface colour 0xcc9e61: red well above blue (the frame and slice lines are not)
    return p[0] > p[2] + 30


def is_background(p):
    return all(abs(a - b) <= 2 for a, b in zip(p, BACKGROUND))


def stats(img, rect):
    """Model pixels in the canvas, and the fractions of model pixels in its centre and of
    background pixels in its four corners (squares of 8% of its height)."""
    x0, y0, w, h = (int(round(rect[k])) for k in ("x", "y", "width", "height"))
    px = img.load()
    model = sum(1 for y in range(y0, y0 + h) for x in range(x0, x0 + w) if is_model(px[x, y]))
    s = int(h * 0.08)
    cx, cy = x0 + w // 2, y0 + h // 2
    centre = [px[x, y] for y in range(cy - s // 2, cy + s // 2) for x in range(cx - s // 2, cx + s // 2)]
    corners = [px[x, y] for (ax, ay) in ((x0, y0), (x0 + w - s, y0), (x0, y0 + h - s), (x0 + w - s, y0 + h - s))
               for y in range(ay, ay + s) for x in range(ax, ax + s)]
    return (model, sum(map(is_model, centre)) / len(centre), sum(map(is_background, corners)) / len(corners))


def main():
    if not shutil.which("chromium"):
        check(False, "chromium is installed (deploy/install-deps.sh installs it)")
        return
    work = tempfile.mkdtemp(prefix="frep-view-test-")
    try:
        run(work)
    finally:
        shutil.rmtree(work, ignore_errors=True)


def run(work):
    # Copies of frep, frep-worker and the modules frep view loads (its server, and the .glb writer
    # of its frep mesh children): the build tree's may be relinked while the test runs.
    os.makedirs(os.path.join(work, "bin"))
    frep = os.path.join(work, "bin", "frep")
    for name in ("frep", "frep-worker", "libfrep_view.so", "libfrep_mesh_files.so"):
        shutil.copy2(os.path.join(os.path.dirname(FREP), name), os.path.join(work, "bin", name))
    model = os.path.join(work, "model.hf")
    save(model, SPHERE)
    server = subprocess.Popen([frep, "view", model, "-b", "-2,2", "--res", "40", "--workers", "2", "--port", "0"],
                              stdout=subprocess.PIPE, stderr=open(os.path.join(work, "view.log"), "w"), text=True,
                              env=dict(os.environ, TMPDIR=work))  # the jobs' temporary folders
    browser = None
    try:
        line = server.stdout.readline()
        check(line.startswith("frep view: http://127.0.0.1:"), "frep view serves on loopback: " + line.strip())
        if not line.startswith("frep view: http://"):
            return
        url = line.split()[2]
        page = urllib.request.urlopen(url).read().decode()
        check("<canvas" in page, "GET / serves the page")
        three = urllib.request.urlopen(url + "node_modules/three/build/three.module.js")
        check("javascript" in three.headers["Content-Type"], "three.js is served locally as JavaScript")

        # Errors of the command itself: exit codes of docs/view.md.
        def view_exit(*args):
            return subprocess.run([frep, "view"] + list(args), capture_output=True, text=True, timeout=20).returncode
        check(view_exit(os.path.join(work, "missing.hf"), "--port", "0") == 3, "a missing model: exit 3")
        check(view_exit(model, "-b", "1,2,3,4", "--port", "0") == 2, "a bad -b: exit 2")
        check(view_exit(model, "--port", url.rstrip("/").rsplit(":", 1)[1]) == 7, "a port in use: exit 7")
        try:  # DNS rebinding: another site's name resolving to 127.0.0.1
            urllib.request.urlopen(urllib.request.Request(url + "api/state", headers={"Host": "evil.example"}))
            check(False, "a request for another host name is refused")
        except urllib.error.HTTPError as e:
            check(e.code == 403, "a request for another host name is refused with 403 (%d)" % e.code)
        try:
            urllib.request.urlopen(url + "api/slice?axis=w&at=0")
            check(False, "a slice along axis w is refused")
        except urllib.error.HTTPError as e:
            check(e.code == 400, "a slice along axis w is refused with 400 (%d)" % e.code)

        browser = Browser(os.path.join(work, "profile"))
        browser.call("Page.navigate", url=url)
        # 1. The sphere: drawn, with the exact silhouette's area.
        if not browser.wait("document.body.dataset.drawn === '1'", 45, "the sphere is drawn"):
            return
        rect = browser.eval("JSON.parse(JSON.stringify(document.getElementById('view').getBoundingClientRect()))")
        img = browser.screenshot("view_sphere.png")
        area1, centre1, corners1 = stats(img, rect)
        # The camera is at distance d = R / sin(fov/2) from the centre (R: half the box's
        # diagonal); a unit sphere's silhouette is a circle of angular radius asin(1/d).
        half = math.radians(35 / 2)
        d = math.sqrt(3) * 2 / math.sin(half)
        radius_px = rect["height"] / 2 * math.tan(math.asin(1 / d)) / math.tan(half)
        exact = math.pi * radius_px ** 2
        print("sphere: %d model pixels, exact silhouette %.0f (ratio %.4f)" % (area1, exact, area1 / exact))
        check(abs(area1 / exact - 1) < 0.06, "sphere's area within 6%% of its exact silhouette (%.4f)" % (area1 / exact))
        check(centre1 > 0.98, "model colour in the middle of the picture (%.3f)" % centre1)
        check(corners1 > 0.98, "background in the corners (%.3f)" % corners1)
        report = browser.eval("document.getElementById('report').textContent")
        check("triangles" in report and "error bound" in report, "the page shows frep mesh's report")
        slice_ok = browser.wait("document.getElementById('slice').naturalWidth > 0", 15, "the slice image is shown")
        check(slice_ok, "the slice image is shown")

        # 2. An edit: the sphere becomes a bigger box, drawn without reloading the page.
        t0 = time.time()
        save(model, BOX)
        if not browser.wait("document.body.dataset.drawn === '2'", 45, "the box is drawn after the save"):
            return
        print("save to drawn: %.2f s" % (time.time() - t0))
        area2, centre2, corners2 = stats(browser.screenshot("view_box.png"), rect)
        print("box: %d model pixels (%.2f x the sphere's)" % (area2, area2 / area1))
        # Its silhouette contains the 3.2-wide square's, 3.2^2 / pi = 3.26 x the unit disc's.
        check(area2 > 3.0 * area1, "the box covers more than 3 times the sphere's pixels (%.2f)" % (area2 / area1))
        check(centre2 > 0.98 and corners2 > 0.98, "box: model in the middle, background in the corners")

        # 3. A syntax error: the message frep prints, file:line:column, shown on the page.
        save(model, BROKEN)
        browser.wait("document.body.dataset.status === 'error' && document.body.dataset.generation === '3'", 30,
                     "the error is shown")
        shown = browser.eval("document.getElementById('error').textContent")
        cli = subprocess.run([frep, "check", model], capture_output=True, text=True).stderr
        first = next((l for l in cli.splitlines() if " error: " in l), "")
        check(first.startswith(model + ":3:"), "frep check names model.hf:3:COL: " + first)
        check(first != "" and first in shown, "the page shows the same line: " + shown.splitlines()[0] if shown else "")
        browser.screenshot("view_error.png")

        # 4. Interruption: a slow model, then a save 1 s later; the slow job is stopped.
        save(model, SLOW)
        browser.wait("document.body.dataset.status === 'computing' && document.body.dataset.generation === '4'", 10,
                     "the slow model is being computed")
        time.sleep(1.0)
        t0 = time.time()
        save(model, SPHERE)
        ok = browser.wait("document.body.dataset.drawn === '5'", 45, "the save after the slow model is drawn")
        state = json.load(urllib.request.urlopen(url + "api/state"))
        print("interrupting save to drawn: %.2f s; interrupted runs: %d" % (time.time() - t0, state["interrupted"]))
        check(ok and state["interrupted"] >= 1, "the slow job was interrupted (%d)" % state["interrupted"])
    finally:
        if browser:
            browser.close()
        server.terminate()
        try:
            rc = server.wait(15)
            check(rc == 0, "frep view exits 0 on SIGTERM (%d)" % rc)
        except subprocess.TimeoutExpired:
            server.kill()
            check(False, "frep view stops within 15 s of SIGTERM")
        leftover = [d for d in os.listdir(work) if d.startswith("frep-view-")]
        check(not leftover, "no temporary folder of a job is left: %s" % leftover)
        if failures:
            print("frep view's log:\n" + open(os.path.join(work, "view.log")).read())


if __name__ == "__main__":
    main()
    print("%d failure(s)" % len(failures))
    sys.exit(1 if failures else 0)
