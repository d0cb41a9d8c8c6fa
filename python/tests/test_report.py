"""chain.report gives `chain report`'s page and JSON for the example calibration; the page is
well-formed HTML (html5lib, strict), self-contained, every number it shows the JSON's; and, in a
real browser (Debian's Chromium, headless), it prints on A4 with a page per section and draws
every chart."""

import hashlib
import json
import os
import pathlib
import re
import shutil
import struct
import subprocess
import zlib

import html5lib
import pytest

import chain
from conftest import ROOT, cli_binary, flat

CALIBRATION = ROOT / "examples" / "calibration" / "vmc3.yaml"


def _at(doc, key):
    for part in key.split("."):
        doc = doc[int(part)] if isinstance(doc, list) else doc[part]
    return doc


def _page():
    out = subprocess.run([str(cli_binary()), "report", str(CALIBRATION)], cwd=ROOT, check=True,
                         capture_output=True, text=True)
    return out.stdout


def test_report_is_the_cli_s(cli, tmp_path):
    out = tmp_path / "report.html"
    r = chain.report(CALIBRATION, out=out)
    assert r.command == "report"
    assert r.to_dict() == cli("report", CALIBRATION)
    assert r.html == _page() == str(r) == out.read_text(encoding="utf-8")
    frame = r.to_dataframe()
    assert list(frame["figure"]) == ["A", "E", "R", "M", "B"]
    assert all(frame["pass"] == (frame["value"].abs() <= frame["tolerance"]))


def test_the_controller_files_are_the_committed_export():
    """The LinuxCNC files the report lists are examples/export/linuxcnc's, by SHA-256 (Python's
    hashlib, independent of the report's)."""
    doc = chain.report(CALIBRATION).to_dict()
    files = doc["export"]["files"]
    committed = sorted(p.name for p in (ROOT / "examples" / "export" / "linuxcnc").iterdir())
    assert sorted(f["path"] for f in files) == committed
    for f in files:
        data = (ROOT / "examples" / "export" / "linuxcnc" / f["path"]).read_bytes()
        assert f["sha256"] == hashlib.sha256(data).hexdigest(), f["path"]
        assert f["bytes"] == len(data)
    for f in doc["inputs"]:
        assert f["sha256"] == hashlib.sha256(pathlib.Path(f["path"]).read_bytes()).hexdigest(), f["path"]


def test_the_page_is_well_formed_self_contained_and_its_documents():
    page = _page()
    # Strict: any parse error (an unclosed or misnested element, a stray character reference)
    # raises.
    tree = html5lib.HTMLParser(strict=True, namespaceHTMLElements=False).parse(page)
    ids = [s.get("id") for s in tree.iter() if s.tag in ("section", "header")]
    assert ids == ["cover", "summary", "positioning-x", "map", "identify", "export", "circular", "thermal",
                   "reproduce"]
    doc = chain.report(CALIBRATION).to_dict()
    checked = 0
    for element in tree.iter():
        key, value = element.get("data-key"), element.get("data-value")
        if key is None:
            continue
        want = _at(doc, key)
        if value is None:
            assert (element.text or "").strip() == want, key
        elif isinstance(want, bool):
            assert value == str(want).lower(), key
        else:
            assert float(value) == want, key
        checked += 1
    assert checked > 200
    # No script, nothing fetched: every attribute is inline.
    assert not tree.findall(".//script") and not tree.findall(".//link") and not tree.findall(".//img")
    for element in tree.iter():
        for name, value in element.attrib.items():
            assert not (name in ("src", "href") or name.endswith("}href")), (element.tag, name, value)
    assert "@import" not in page and "url(" not in page


def _chromium():
    for name in ("chromium", "chromium-browser", "google-chrome"):
        path = shutil.which(name)
        if path:
            return path
    if os.environ.get("CHAIN_REQUIRE_BROWSER"):
        pytest.fail("CHAIN_REQUIRE_BROWSER is set but no Chromium is installed")
    pytest.skip("no Chromium (CI installs Debian's chromium: .ci/run)")


def _headless(browser, profile, *args):
    cmd = [browser, "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
           "--disable-background-networking", "--disable-component-update", "--disable-sync",
           f"--user-data-dir={profile}", *args]
    subprocess.run(cmd, check=True, capture_output=True, timeout=180)


def _png_rgb(path):
    """The RGB rows of an 8-bit RGB or RGBA PNG (the standard's filters; no other library)."""
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    pos, idat, width = 8, b"", 0
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, colour = struct.unpack(">IIBB", body[:10])
            assert depth == 8 and colour in (2, 6), (depth, colour)
            channels = 3 if colour == 2 else 4
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    raw = zlib.decompress(idat)
    stride = width * channels
    rows, prev = [], bytearray(stride)
    for y in range(height):
        f, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - channels] if i >= channels else 0
            b, c = prev[i], (prev[i - channels] if i >= channels else 0)
            if f == 1:
                line[i] = (line[i] + a) & 255
            elif f == 2:
                line[i] = (line[i] + b) & 255
            elif f == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(bytes(line[j] for j in range(stride) if j % channels < 3))
        prev = line
    return width, rows


def test_a_real_browser_prints_the_page_and_draws_every_chart(tmp_path):
    browser = _chromium()
    page = tmp_path / "report.html"
    page.write_text(_page(), encoding="utf-8")
    # Printed on A4: a page at least per section (each starts on a new page), the pages A4.
    pdf = tmp_path / "report.pdf"
    _headless(browser, tmp_path / "profile", "--no-pdf-header-footer", f"--print-to-pdf={pdf}", page.as_uri())
    data = pdf.read_bytes()
    pages = len(re.findall(rb"/Type\s*/Page(?![s\w])", data))
    sections = page.read_text().count('class="page"')
    assert sections == 8
    assert sections + 1 <= pages <= 60, pages
    boxes = {tuple(round(float(v)) for v in m) for m in re.findall(rb"/MediaBox\s*\[\s*0 0 ([\d.]+) ([\d.]+)\s*\]", data)}
    assert boxes == {(595, 842)}, boxes  # A4 in points
    # Every chart drawn: the page with each chart placed in a known box of its own (the rest of
    # the page hidden), screenshot, and every box holds ink (pixels well away from white) over
    # much of its area.
    text = page.read_text()
    charts = text.count('<figure class="chart">')
    assert charts >= 10
    h, w = 420, 560
    k = iter(range(charts))
    placed = re.sub('<figure class="chart">',
                    lambda _: (lambda i: f'<figure class="chart" style="visibility:visible;position:absolute;margin:0;'
                               f'left:0;top:{i * h}px;width:{w}px;height:{h}px">')(next(k)), text)
    placed = placed.replace("</style>", "body{max-width:none;margin:0} header,section{visibility:hidden}"
                                         "figure.chart svg{width:100%;height:100%;max-height:none}</style>")
    shot_page = tmp_path / "charts.html"
    shot_page.write_text(placed, encoding="utf-8")
    shot = tmp_path / "charts.png"
    _headless(browser, tmp_path / "profile", "--hide-scrollbars", f"--window-size={w},{charts * h}",
              f"--screenshot={shot}", shot_page.as_uri())
    width, rows = _png_rgb(shot)
    assert width == w and len(rows) >= charts * h
    for i in range(charts):
        inked = 0
        for y in range(i * h, (i + 1) * h, 4):
            row = rows[y]
            inked += sum(1 for x in range(0, w * 3, 12) if min(row[x:x + 3]) < 200)
        samples = (h // 4) * (w // 4)
        assert inked > 0.01 * samples, (i, inked, samples)


def test_a_refused_calibration_is_the_cli_s(cli_error, tmp_path):
    bad = tmp_path / "calibration.yaml"
    bad.write_text("machine: no/such/machine.yaml\n")
    with pytest.raises(chain.MachineError) as e:
        chain.report(bad)
    assert "calibration.yaml:1" in str(e.value) and "cannot read" in str(e.value)
    assert "no/such/machine.yaml" in flat(cli_error("report", bad))
