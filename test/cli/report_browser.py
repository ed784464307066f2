#!/usr/bin/env python3
"""Opens `clfractal report` pages in headless Chromium over the DevTools protocol and checks
the interactive view as a reader meets it.

report_browser.py [--load-only] [--held-out PAGE.html] [--views-png OUT.png] CHROMIUM REPORT_CHECK WORKDIR PAGE.html [PAGE.html ...]
  for each page (file://, SwiftShader WebGL):
  - it is at most 8 MB, it loads, and the first 3D view ("where the noise is") has rendered
    the first control's isovalue;
  - the first WebGL canvas (screenshot of its rectangle) shows the LD colour map's red end,
    and its blue end too on a --held-out page (the acceptance on a held-out MRI head), or
    else the first or the second view shows it (report_check canvas: >= 0.5% each): the
    noisiest surface of a synthetic volume may be red all over;
  - there are >= 2 data-isovalue controls, and a real click on the second renders its
    isovalue and changes >= 5% of the first canvas;
  - the second 3D view, when the page has one, shows the recommended surface, and dragging
    the first view turns it too (>= 5% of its pixels change);
  - pointing at the D(s) plot shows the isovalue's numbers;
  - no console error, no exception, and no request other than the page itself and data:.
  With --load-only (every volume of a collection, whose surfaces need not show both ends of
  the colour map): the size, the load, the first view rendered, a click on the second control
  rendering its isovalue, the console and the requests; the colour shares are printed.
  With --views-png, the switch and the two 3D views of the first page as it opens (the
  picture of docs/guide/report.md).
Exit 0 when all hold, 1 with one line per failure.
"""
import argparse
import base64
import json
import os
import re
import subprocess
import sys
import time
import urllib.request

import websocket

failures = []


def fail(msg):
    failures.append(msg)
    print("FAIL: " + msg, flush=True)


class Tab:
    def __init__(self, ws_url):
        self.ws = websocket.create_connection(ws_url, timeout=30, suppress_origin=True)
        self.next_id = 0
        self.events = []

    def call(self, method, **params):
        self.next_id += 1
        self.ws.send(json.dumps({"id": self.next_id, "method": method, "params": params}))
        while True:
            msg = json.loads(self.ws.recv())
            if msg.get("id") == self.next_id:
                if "error" in msg:
                    raise RuntimeError("%s: %s" % (method, msg["error"]))
                return msg.get("result", {})
            self.events.append(msg)

    def evaluate(self, expression):
        r = self.call("Runtime.evaluate", expression=expression, returnByValue=True)
        if "exceptionDetails" in r:
            raise RuntimeError("evaluate %s: %s" % (expression, r["exceptionDetails"].get("text")))
        return r["result"].get("value")

    def wait_for(self, expression, seconds):
        end = time.time() + seconds
        while time.time() < end:
            if self.evaluate(expression):
                return True
            time.sleep(0.1)
        return False

    def shot(self, rect, path, scale=1):
        clip = dict(x=rect["x"], y=rect["y"], width=rect["width"], height=rect["height"], scale=scale)
        data = self.call("Page.captureScreenshot", format="png", clip=clip)["data"]
        with open(path, "wb") as f:
            f.write(base64.b64decode(data))

    def click(self, x, y):
        for kind in ("mouseMoved", "mousePressed", "mouseReleased"):
            self.call("Input.dispatchMouseEvent", type=kind, x=x, y=y, button="left", clickCount=1)


def canvas_rect(tab, holder="view3d"):
    return tab.evaluate("(function(){var c=document.querySelector('#" + holder + " canvas');c.scrollIntoView();"
                        "var r=c.getBoundingClientRect();return {x:r.left+scrollX,y:r.top+scrollY,"
                        "width:r.width,height:r.height};})()")


def changed_share(a, b):
    """The share of pixels whose colours differ by more than 24 (sum over R, G, B) from a to b
    (Pillow, which the build's venv has with matplotlib)."""
    import numpy
    from PIL import Image
    pa, pb = (numpy.asarray(Image.open(p).convert("RGB"), dtype=int) for p in (a, b))
    return float((numpy.abs(pa - pb).sum(axis=2) > 24).mean())


def click_control(tab, name, controls, i):
    box = tab.evaluate("(function(){var b=document.querySelectorAll('[data-isovalue]')[%d];b.scrollIntoView();"
                       "var r=b.getBoundingClientRect();return {x:r.left+r.width/2,y:r.top+r.height/2};})()" % i)
    tab.click(box["x"], box["y"])
    if not tab.wait_for("document.getElementById('view3d').dataset.rendered === %s" % json.dumps(controls[i]), 10):
        fail(name + ": clicking control %d did not render isovalue %s" % (i + 1, controls[i]))


def second_view(tab, name):
    """The second view's choice, None when the page has none."""
    ref = tab.evaluate("(function(){var h=document.getElementById('view3d-ref');if(!h||h.parentNode.hidden)"
                       "return null;var c=JSON.parse(document.getElementById('report-choices').textContent)"
                       "[+h.dataset.choice];return {rendered:h.dataset.rendered,text:c.text,role:c.role};})()")
    if ref is None:
        print(name + ": no second view (the switched view opens on the recommendation)", flush=True)
    elif ref["rendered"] != ref["text"] or not re.match(r"(recommended|cleanest)", ref["role"]):
        fail(name + ": the second view shows %r, a %r choice %r" % (ref["rendered"], ref["role"], ref["text"]))
    return ref


def check_linked(tab, name, work, before):
    """Dragging the first view turns the second (screenshot `before`) too."""
    after = os.path.join(work, name + "-ref-turned.png")
    r = canvas_rect(tab)
    tab.evaluate("scrollTo(0, %f)" % r["y"])
    x, y = r["x"] + r["width"] / 2, r["height"] / 2
    tab.call("Input.dispatchMouseEvent", type="mousePressed", x=x, y=y, button="left", clickCount=1)
    for step in range(1, 9):
        tab.call("Input.dispatchMouseEvent", type="mouseMoved", x=x + 20 * step, y=y, button="left", buttons=1)
    tab.call("Input.dispatchMouseEvent", type="mouseReleased", x=x + 160, y=y, button="left", clickCount=1)
    tab.shot(canvas_rect(tab, "view3d-ref"), after)
    share = changed_share(before, after)
    print("%s: dragging the first view changed %.1f%% of the second" % (name, 100 * share), flush=True)
    if share < 0.05:
        fail(name + ": dragging the first view did not turn the second")


def views_png(tab, path):
    """The switch, the two 3D views and the colour bar under them, at 3/4 scale."""
    rect = tab.evaluate("(function(){var s=document.querySelector('#explore .switch');s.scrollIntoView();"
                        "var p=document.getElementById('view3d').parentNode.parentNode,a=s.getBoundingClientRect(),"
                        "b=p.nextElementSibling.getBoundingClientRect();return {x:a.left+scrollX,y:a.top+scrollY,"
                        "width:a.width,height:b.bottom-a.top};})()")
    tab.shot(rect, path, 0.75)
    print("wrote %s (%d bytes)" % (path, os.path.getsize(path)), flush=True)


def check_page(tab, check, page, work, name, load_only, held_out, views=None):
    url = "file://" + os.path.realpath(page)
    size = os.path.getsize(page)
    print("%s: %.2f MB" % (name, size / 1e6), flush=True)
    if size > 8 << 20:
        fail(name + ": the page is %d bytes, more than 8 MB" % size)
    del tab.events[:]
    tab.call("Page.navigate", url=url)
    if not tab.wait_for("document.readyState === 'complete' && !!document.getElementById('view3d') && "
                        "document.getElementById('view3d').dataset.rendered !== undefined", 30):
        fail(name + ": the 3D view did not render")
        return check_events(tab, name, url)
    controls = tab.evaluate("Array.from(document.querySelectorAll('[data-isovalue]')).map(function(b){"
                            "return b.dataset.isovalue;})")
    first = tab.evaluate("document.getElementById('view3d').dataset.rendered")
    if first != controls[0]:
        fail(name + ": the view shows %r, the first control is %r" % (first, controls[0]))
    if views:
        views_png(tab, views)
    a, b, ref = (os.path.join(work, name + tail) for tail in ("-first.png", "-second.png", "-ref.png"))
    tab.shot(canvas_rect(tab), a)
    second = None if load_only else second_view(tab, name)
    if second:
        tab.shot(canvas_rect(tab, "view3d-ref"), ref)
    if len(controls) < 2:
        if not load_only:
            fail(name + ": %d data-isovalue controls, expected >= 2" % len(controls))
    else:
        click_control(tab, name, controls, 1)
        tab.shot(canvas_rect(tab), b)
        r = subprocess.run([check, "canvas", a, b] + ([ref] if second and not held_out else []),
                           capture_output=True, text=True)
        said = r.stdout.strip().replace("\n", "; ")
        if load_only:  # the pixel rules are not checked on these pages: say so, not "FAIL"
            said = "not checked on this page: " + said.replace("FAIL: ", "")
        print(name + ": " + said, flush=True)
        if r.returncode != 0 and not load_only:
            fail(name + ": report_check canvas")
    if second:
        check_linked(tab, name, work, ref)
    if not load_only:
        check_hover(tab, name)
    check_events(tab, name, url)


def check_hover(tab, name):
    """Pointing at the D(s) plot shows the numbers of an isovalue."""
    at = tab.evaluate("(function(){var s=document.getElementById('plot-fd');s.scrollIntoView();"
                      "var r=s.getBoundingClientRect();return {x:r.left+r.width*0.5,y:r.top+r.height*0.5};})()")
    tab.call("Input.dispatchMouseEvent", type="mouseMoved", x=at["x"], y=at["y"])
    tip = tab.evaluate("document.getElementById('tip').hidden ? '' : document.getElementById('tip').textContent")
    if not re.search(r"isovalue .* D = .* count I\(s\) = \d+ .*components = \d+ .*verdict: \w+ .*r\(s\) = ", tip or ""):
        fail(name + ": pointing at the D(s) plot shows %r" % tip)


def check_events(tab, name, url):
    """No exception, console error or log error, no request but the page and data: URIs."""
    tab.call("Runtime.evaluate", expression="0")
    for e in tab.events:
        method, p = e.get("method"), e.get("params", {})
        if method == "Runtime.exceptionThrown":
            fail(name + ": exception " + json.dumps(p.get("exceptionDetails", {}))[:300])
        elif method == "Runtime.consoleAPICalled" and p.get("type") in ("error", "assert"):
            fail(name + ": console error " + json.dumps(p.get("args"))[:300])
        elif method == "Log.entryAdded" and p.get("entry", {}).get("level") == "error":
            fail(name + ": log error " + p["entry"].get("text", "")[:300])
        elif method == "Network.requestWillBeSent":
            u = p.get("request", {}).get("url", "")
            if u != url and not u.startswith("data:"):
                fail(name + ": a request to " + u[:120])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--load-only", action="store_true")
    ap.add_argument("--held-out", action="append", default=[], help="a page held to the acceptance as written")
    ap.add_argument("--views-png", help="write the first page's two 3D views as they open to this PNG")
    ap.add_argument("browser")
    ap.add_argument("check")
    ap.add_argument("work")
    ap.add_argument("pages", nargs="*")
    args = ap.parse_args()
    if not args.pages and not args.held_out:
        ap.error("no page")
    browser, check, work, load_only = args.browser, args.check, args.work, args.load_only
    pages = args.pages + args.held_out
    held_out = {os.path.realpath(p) for p in args.held_out}
    os.makedirs(work, exist_ok=True)
    env = dict(os.environ, HOME=os.path.join(work, "home"))
    proc = subprocess.Popen([browser, "--headless", "--no-sandbox", "--use-angle=swiftshader",
                             "--enable-unsafe-swiftshader", "--hide-scrollbars", "--no-first-run",
                             "--window-size=1200,1400", "--remote-debugging-port=0",
                             "--user-data-dir=" + os.path.join(work, "profile"), "about:blank"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, env=env)
    try:
        port = None
        end = time.time() + 30
        while time.time() < end and port is None:
            line = proc.stderr.readline()
            if not line and proc.poll() is not None:
                break
            m = re.search(r"DevTools listening on ws://127\.0\.0\.1:(\d+)/", line)
            if m:
                port = int(m.group(1))
        if port is None:
            fail("chromium did not open its DevTools port")
            return 1
        targets = json.load(urllib.request.urlopen("http://127.0.0.1:%d/json/list" % port, timeout=10))
        page_target = [t for t in targets if t.get("type") == "page"][0]
        tab = Tab(page_target["webSocketDebuggerUrl"])
        for domain in ("Page", "Runtime", "Log", "Network"):
            tab.call(domain + ".enable")
        for i, page in enumerate(pages):
            t0 = time.time()
            check_page(tab, check, page, work, os.path.splitext(os.path.basename(page))[0], load_only,
                       os.path.realpath(page) in held_out, args.views_png if i == 0 else None)
            print("%s: checked in %.1f s" % (page, time.time() - t0), flush=True)
    finally:
        proc.terminate()
        try:
            proc.wait(10)
        except subprocess.TimeoutExpired:
            proc.kill()
    print("browser: %d pages, %d failures" % (len(pages), len(failures)))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
