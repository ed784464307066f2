#!/usr/bin/env python3
"""Checks the structure of a `clfractal report` page against its --json (stdlib only).

report_check.py REPORT.html REPORT.json
  - the sections are there (volume, answer, recommended, bands, fd, components, d4, and one
    view per picture set the JSON lists);
  - every image is a data:image/png;base64 URI that decodes to a valid PNG (signature,
    chunk CRCs, IHDR first and IEND last, IDAT inflating to the size IHDR implies);
  - nothing is fetched: no http(s):// outside scripts, and inside them only in comments or
    as the XHTML and SVG namespace names (never requested); no src/href other than data:
    URIs; scripts only inline (no src), no link, iframe, object, embed, base or CSS url();
  - with the interactive view (JSON "explore" with "choices"): the section, one data-isovalue
    control per choice, the JSON and the meshes inline, three.js inlined, every mesh at most
    300000 triangles; without it (--static, or three.js missing) no script at all;
  - the JSON has the keys the report promises;
  - every number of the page (span data-json="/pointer") equals the JSON's: integers
    exactly, floats as printf %.*g with the page's data-digits;
  - the recommended table has one row per recommended isovalue.
Exit 0 when all hold, 1 with one line per failure.
"""
import base64
import json
import re
import struct
import sys
import zlib
from html.parser import HTMLParser

failures = []


def fail(msg):
    failures.append(msg)
    print("FAIL: " + msg)


class Page(HTMLParser):
    def __init__(self):
        super().__init__()
        self.tags = []          # (tag, attrs)
        self.sections = []      # ids
        self.numbers = []       # (pointer, digits, text)
        self._num = None
        self.tables = {}        # section id -> data rows
        self._section = None
        self.scripts = []       # (attrs, text)
        self._script = None

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        self.tags.append((tag, a))
        if tag == "section":
            self._section = a.get("id")
            self.sections.append(self._section)
        if tag == "tr" and self._section:
            self.tables.setdefault(self._section, 0)
        if tag == "td" and self._section and self._last_tr_counted is False:
            self.tables[self._section] += 1
            self._last_tr_counted = True
        if tag == "tr":
            self._last_tr_counted = False
        if tag == "span" and "data-json" in a:
            self._num = [a["data-json"], a.get("data-digits"), ""]
        if tag == "script":
            self._script = [a, ""]

    _last_tr_counted = True

    def handle_endtag(self, tag):
        if tag == "script" and self._script is not None:
            self.scripts.append(tuple(self._script))
            self._script = None
        if tag == "span" and self._num is not None:
            self.numbers.append(tuple(self._num))
            self._num = None
        if tag == "section":
            self._section = None

    def handle_data(self, data):
        if self._script is not None:
            self._script[1] += data
        if self._num is not None:
            self._num[2] += data


def check_png(data, what):
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        return fail(what + ": not a PNG signature")
    pos, chunks, idat = 8, [], b""
    while pos < len(data):
        if pos + 8 > len(data):
            return fail(what + ": truncated chunk header")
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        crc = data[pos + 8 + length:pos + 12 + length]
        if len(body) != length or len(crc) != 4:
            return fail(what + ": truncated chunk")
        if struct.unpack(">I", crc)[0] != zlib.crc32(kind + body) & 0xFFFFFFFF:
            return fail(what + ": bad CRC in " + kind.decode("latin-1"))
        chunks.append((kind, body))
        if kind == b"IDAT":
            idat += body
        pos += 12 + length
    if not chunks or chunks[0][0] != b"IHDR" or chunks[-1][0] != b"IEND":
        return fail(what + ": IHDR must come first and IEND last")
    w, h, depth, colour, _, _, interlace = struct.unpack(">IIBBBBB", chunks[0][1])
    channels = {0: 1, 2: 3, 3: 1, 4: 2, 6: 4}.get(colour)
    if channels is None or w == 0 or h == 0 or interlace != 0:
        return fail(what + ": unexpected IHDR %r" % ((w, h, depth, colour, interlace),))
    raw = zlib.decompress(idat)
    want = h * (1 + (w * channels * depth + 7) // 8)
    if len(raw) != want:
        return fail(what + ": IDAT holds %d bytes, IHDR implies %d" % (len(raw), want))
    return (w, h)


def check_plot(plot, data):
    """The curves' inline columns equal the JSON (D to 6 digits, r(s) to 4)."""
    curve = data["curve"]
    ratio = {e["isovalue"]: e["ratio"] for e in data["noise"].get("surface", {}).get("per_isovalue", [])}
    if len(plot["isovalue"]) != len(curve):
        return fail("plot data: %d isovalues, the JSON %d" % (len(plot["isovalue"]), len(curve)))
    for i, e in enumerate(curve):
        got = (plot["isovalue"][i], plot["fd"][i], plot["count"][i], plot["components"][i],
               plot["verdicts"][plot["verdict"][i]], plot["ratio"][i])
        r = ratio.get(e["isovalue"])
        want = (e["isovalue"], None if e["fd"] is None else float("%.6g" % e["fd"]), e["counts"][0], e["components"],
                e["verdict"], None if r is None else float("%.4g" % r))
        if got != want:
            return fail("plot data at isovalue %r: %r, the JSON %r" % (e["isovalue"], got, want))
    if plot["recommended"] != [r["isovalue"] for r in data["recommended"]] or \
            plot["noisiest"] != (data["noisiest"] or {}).get("isovalue") or \
            plot["clean_bands"] != [[b["first"], b["last"]] for b in data["clean_bands"]] or \
            plot["clean_fd"] != data["advice"]["clean_fd"]:
        fail("plot data: the marks differ from the JSON")


def resolve(doc, pointer):
    for part in pointer.split("/")[1:]:
        part = part.replace("~1", "/").replace("~0", "~")
        doc = doc[int(part)] if isinstance(doc, list) else doc[part]
    return doc


def main():
    html_path, json_path = sys.argv[1], sys.argv[2]
    text = open(html_path, encoding="utf-8").read()
    data = json.load(open(json_path))
    page = Page()
    page.feed(text)

    # JSON keys.
    for key in ["volume", "recommended", "fd4", "clean_bands", "clean", "noise", "noisiest", "views", "isovalues",
                "advice", "fd", "denoise", "curve", "explore"]:
        if key not in data:
            fail("JSON: no key " + key)
    for key in ["file", "format", "dims", "type", "spacing", "value_range"]:
        if key not in data.get("volume", {}):
            fail("JSON: no key volume/" + key)
    for key in ["sigma", "flat_share", "map", "surface"]:
        if key not in data.get("noise", {}):
            fail("JSON: no key noise/" + key)
    for key in ["amplitude", "ratio", "isovalues_used"]:
        if key not in data.get("noise", {}).get("surface", {}):
            fail("JSON: no key noise/surface/" + key)
    for r in data.get("recommended", []):
        for key in ["isovalue", "fd", "count", "count_sub", "components", "verdict", "first", "last", "noise_ratio"]:
            if key not in r:
                fail("JSON: a recommended entry has no " + key)

    # Sections.
    want = ["volume", "answer", "recommended", "bands", "fd", "components", "d4"]
    if data.get("denoise", {}).get("attempts"):
        want.append("denoise")
    want += ["view-%d" % i for i in range(len(data.get("views", [])))]
    for s in want:
        if s not in page.sections:
            fail("HTML: no section " + s)

    # Self-contained: images inline, nothing fetched.
    outside = re.sub(r"<script\b.*?</script\s*>", "", text, flags=re.I | re.S)
    if re.search(r"https?://", outside, re.I):
        fail("HTML: an http(s):// reference")
    if re.search(r"url\s*\(", outside, re.I):
        fail("HTML: a CSS url()")
    namespaces = ("http://www.w3.org/1999/xhtml", "http://www.w3.org/2000/svg")
    for attrs, body in page.scripts:
        for line in body.splitlines():
            for m in re.finditer(r"https?://", line, re.I):
                before = line[:m.start()]
                if line[m.start():].startswith(namespaces) or "//" in before or before.strip().startswith("*"):
                    continue
                fail("HTML: a script holds %r outside a comment" % line[m.start():m.start() + 60])
        if attrs.get("type") not in (None, "application/json"):
            fail("HTML: a script of type %r" % attrs.get("type"))
    mine = [body for attrs, body in page.scripts if attrs.get("id") == "report-script"]
    for body in mine:
        for api in ("fetch(", "XMLHttpRequest", "import(", "WebSocket", "sendBeacon", "EventSource", "location"):
            if api in body:
                fail("HTML: the report's script uses " + api)
    explore = data.get("explore", {})
    choices = explore.get("choices")
    controls = [a for t, a in page.tags if "data-isovalue" in a]
    if choices:
        if "explore" not in page.sections:
            fail("HTML: no section explore")
        if len(controls) != len(choices):
            fail("HTML: %d data-isovalue controls, %d choices" % (len(controls), len(choices)))
        for a, c in zip(controls, choices):
            # The isovalue as the library names it: exact, or %.9g on float32 data.
            if float(a["data-isovalue"]) != c["isovalue"] and a["data-isovalue"] != "%.9g" % c["isovalue"]:
                fail("HTML: data-isovalue %r, the JSON %r" % (a["data-isovalue"], c["isovalue"]))
            if not 0 < c["triangles"] <= 300000 or c["triangles"] > c["triangles_full"]:
                fail("JSON: a mesh of %d triangles (of %d)" % (c["triangles"], c["triangles_full"]))
        ids = {a.get("id") for a, _ in page.scripts}
        for want_id in ("report-plot", "report-choices", "report-script"):
            if want_id not in ids:
                fail("HTML: no script " + want_id)
        if not any("OrbitControls" in b for _, b in page.scripts) or not any("WebGLRenderer" in b for _, b in page.scripts):
            fail("HTML: three.js and its OrbitControls are not inlined")
        if not mine or not mine[0].strip():
            fail("HTML: the report's script is empty")
        elif len(mine) == 1:
            try:
                check_plot(json.loads([b for a, b in page.scripts if a.get("id") == "report-plot"][0]), data)
            except (ValueError, IndexError, KeyError, TypeError) as e:
                fail("HTML: the curves' inline data does not parse: %r" % e)
    else:
        if page.scripts or controls:
            fail("HTML: scripts or data-isovalue controls on a page without the interactive view")
        if "explore" in page.sections:
            fail("HTML: a section explore without choices")
    images = 0
    for tag, attrs in page.tags:
        if tag in ("link", "iframe", "object", "embed", "base"):
            fail("HTML: a <%s> element" % tag)
        if tag == "script" and "src" in attrs:
            fail("HTML: a script with src")
        for name in ("src", "href", "srcset", "poster", "data"):
            value = attrs.get(name)
            if value is None:
                continue
            if tag == "img" and name == "src" and value.startswith("data:image/png;base64,"):
                images += 1
                size = check_png(base64.b64decode(value.split(",", 1)[1], validate=True), "image %d" % images)
                if size and (size[0] < 200 or size[1] < 150):
                    fail("image %d is only %dx%d" % (images, size[0], size[1]))
            else:
                fail("HTML: <%s %s=%r> is not an inline PNG" % (tag, name, value[:60]))
    want_images = 2 + 2 * len(data.get("views", []))
    if images != want_images:
        fail("HTML: %d inline images, expected %d (two curves, mesh and slice per view)" % (images, want_images))

    # Numbers equal the JSON.
    equal = 0
    for pointer, digits, shown in page.numbers:
        try:
            value = resolve(data, pointer)
        except (KeyError, IndexError, ValueError):
            fail("HTML number %s: not in the JSON" % pointer)
            continue
        if value is None:
            expected = "n/a"
        elif isinstance(value, bool) or not isinstance(value, (int, float)):
            fail("HTML number %s: the JSON holds %r" % (pointer, value))
            continue
        elif isinstance(value, int):
            expected = str(value)
        else:
            expected = "%.*g" % (int(digits), value)
        if shown.strip() != expected:
            fail("HTML number %s shows %r, the JSON %r" % (pointer, shown, expected))
        else:
            equal += 1
    pointers = {p for p, _, _ in page.numbers}
    for i in range(len(data.get("recommended", []))):
        for key in ["isovalue", "fd", "count", "components", "noise_ratio"]:
            if "/recommended/%d/%s" % (i, key) not in pointers:
                fail("HTML: recommended %d has no %s" % (i, key))
    shown = ["/fd4/d4", "/volume/dims/0", "/volume/spacing/0", "/volume/value_range/1"]
    if data.get("recommended"):
        shown += ["/noise/sigma", "/noise/surface/ratio"]
    for p in shown:
        if p not in pointers:
            fail("HTML: the number " + p + " is not shown")
    rows = page.tables.get("recommended", 0)
    if rows != len(data.get("recommended", [])):
        fail("HTML: %d recommended rows, JSON %d" % (rows, len(data.get("recommended", []))))

    print("html: %d sections, %d inline PNGs, %d numbers equal to the JSON, %d recommended, %d failures"
          % (len(page.sections), images, equal, len(data.get("recommended", [])), len(failures)))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
