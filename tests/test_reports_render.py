"""The HTML reports as a user sees them (issue 16): rendered by headless Chromium, every
picture loads and the visible text holds no nan, None, True/False or Python repr. Skipped
where no Chromium is installed (.ci/run installs Debian's)."""

from __future__ import annotations

import json
import re
import shutil
import subprocess
from html.parser import HTMLParser
from pathlib import Path

import pytest

from compare.cli import main

CHROMIUM = next((p for p in (shutil.which(n) for n in ("chromium", "chromium-browser",
                                                         "google-chrome", "chrome")) if p), None)
pytestmark = pytest.mark.skipif(CHROMIUM is None, reason="no Chromium on this machine")

#: what a Python value printed into a page looks like: a bare nan/None/True/False word, a
#: dict or list repr with quoted keys, an object repr
REPR = re.compile(r"\b(nan|NaN|None|True|False)\b|\{'|\['|<[a-z_.]+ object at 0x")
PROBE = ("<script>window.addEventListener('load', () => {"
         "const broken = [...document.images].filter(i => !i.complete || i.naturalWidth === 0);"
         "const out = document.createElement('pre'); out.id = 'probe';"
         "out.textContent = JSON.stringify({images: document.images.length,"
         " broken: broken.length, text: document.body.innerText});"
         "document.body.appendChild(out);});</script>")


class _Probe(HTMLParser):
    def __init__(self):
        super().__init__()
        self.inside, self.data = False, ""

    def handle_starttag(self, tag, attrs):
        self.inside = self.inside or (tag == "pre" and ("id", "probe") in attrs)

    def handle_data(self, data):
        if self.inside:
            self.data += data

    def handle_endtag(self, tag):
        if tag == "pre":
            self.inside = False


def render(page: Path, tmp: Path) -> dict:
    """The page as Chromium lays it out: number of images, broken images, visible text."""
    probe = tmp / f"probe-{page.parent.name}.html"
    probe.write_text(page.read_text(encoding="utf-8").replace("</body>", PROBE + "</body>"),
                     encoding="utf-8")
    dom = subprocess.run(
        [CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic",
         "--no-first-run", "--disable-background-networking", "--disable-component-update",
         "--disable-sync", f"--user-data-dir={tmp / 'chromium-profile'}",
         "--virtual-time-budget=10000", "--dump-dom", probe.as_uri()],
        capture_output=True, text=True, timeout=120, check=True).stdout
    p = _Probe()
    p.feed(dom)
    return json.loads(p.data)


def _check(page: Path, tmp: Path, min_images: int) -> str:
    seen = render(page, tmp)
    assert seen["images"] >= min_images and seen["broken"] == 0, seen
    text = seen["text"]
    bad = sorted({m.group(0) for m in REPR.finditer(text)})
    assert not bad, (page, bad)
    return text


def test_study_report_renders(tmp_path):
    out = tmp_path / "study"
    assert main(["study", "fin-shaft", "--levels", "0", "1", "2", "--nodes", "3", "11",
                 "--steady-only", "--quiet", "--out", str(out)]) == 0
    text = _check(out / "report.html", tmp_path, min_images=4)
    assert "PASS" in text or "FAIL" in text  # the verdicts in words
    assert "Checked against the FEM reference" in text  # the summary paragraph


def test_fit_report_renders(tmp_path):
    run = tmp_path / "run.csv"
    assert main(["synth", "--effect", "fixture_expansion", "--seed", "2", "--level", "0",
                 "--out", str(run)]) == 0
    out = tmp_path / "fit"
    own = tmp_path / "mine.toml"  # criteria of one's own reach the report; options go over them
    own.write_text("cv_blocks = 0\nalpha = 0.05\nmaterial_peak = 0.6\n")
    assert main(["fit", str(run), "--out", str(out), "--quiet", "--criteria", str(own),
                 "--alpha", "0.02", "--candidates", "fixture_expansion",
                 "centrifugal_shortening"]) == 0
    doc = json.loads((out / "report.json").read_text())
    used = {c["name"]: c["value"] for c in doc["criteria"]}
    assert (used["cv_blocks"], used["alpha"], used["material_peak"]) == (0, 0.02, 0.6)
    assert doc["alpha"] == 0.02 and doc["cross_validation"] == {}
    # the fit report's two pictures: channels and residuals (compare.fit.report._pictures)
    text = _check(out / "report.html", tmp_path, min_images=2)
    assert "Signature tests" in text and "Candidates and criteria" in text
