"""Report building blocks shared by every feature: number formatting, Markdown tables, HTML
tables and self-contained figures (PNG embedded as base64), and the page frame.

Computing and presenting stay apart: features build their numbers, then call these to show them.
"""

from __future__ import annotations

import base64
import html
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

#: the look shared by every report.html
CSS = ("body{font-family:sans-serif;max-width:1200px;margin:2em auto;color:#222}"
       # a table wider than the page scrolls inside its own box (its last columns, the
       # verdicts, stay reachable in a narrow window)
       "table{border-collapse:collapse;font-size:12px;margin:1em 0;display:block;"
       "overflow-x:auto;max-width:100%}"
       "td,th{border:1px solid #ccc;padding:2px 6px;text-align:right}"
       "th{background:#f2f2f2}img{max-width:100%}figcaption{font-size:12px;color:#555}"
       "td.pass{background:#d9f2d9;color:#145214;font-weight:bold;text-align:center}"
       "td.fail{background:#f8d7d7;color:#7a1010;font-weight:bold;text-align:center}"
       "td.borderline{background:#fff3cd;color:#6b4e00;font-weight:bold;text-align:center}"
       "p.summary{font-size:15px;background:#f6f6f6;padding:0.6em 0.8em;border-left:4px solid "
       "#888}td:last-child{min-width:12em}")


def verdict_cell(ok: bool | None, borderline: bool = False) -> str:
    """A table cell saying PASS, FAIL or, where the margin is within the reference's own
    uncertainty, "borderline" (with the side it falls on), in words and colour (n/a without
    a verdict)."""
    if ok is None:
        return "<td>n/a</td>"
    if borderline:
        return f'<td class="borderline">borderline ({"passes" if ok else "fails"})</td>'
    return '<td class="pass">PASS</td>' if ok else '<td class="fail">FAIL</td>'

MISSING = "—"


def fmt(v: Any, spec: str = ".4g") -> str:
    """One table cell: floats with ``spec``, None and NaN as a dash, anything else as str."""
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return MISSING
    if isinstance(v, float):
        return format(v, spec)
    return str(v)


#: a machine name's unit suffix and how a person reads it (tables for people; JSON and CSV
#: keep the machine names)
UNITS = {"K": "K", "C": "°C", "um": "µm", "m": "m", "pct": "%", "s": "s", "W": "W",
         "rpm": "rpm", "Nm": "N m", "J": "J"}


def human_header(name: str) -> str:
    """A column's machine name as words with its unit: ``GCI_fine_pct`` -> ``GCI fine [%]``,
    ``P1_max_um`` -> ``P1 max [µm]``, ``meets_tolerances`` -> ``meets tolerances``."""
    head, _, unit = name.rpartition("_")
    if head and unit in UNITS:
        return f"{head.replace('_', ' ')} [{UNITS[unit]}]"
    return name.replace("_", " ")


def markdown_table(header: Sequence[str], rows: Sequence[Sequence[Any]],
                   fmts: Sequence[str] | None = None) -> str:
    """A Markdown table for people: headers as words with units (:func:`human_header`);
    ``fmts`` gives one format spec per column (default ``.4g``)."""
    fmts = list(fmts or [".4g"] * len(header))
    header = [human_header(str(h)) for h in header]
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    for r in rows:
        lines.append("| " + " | ".join(fmt(v, f) for v, f in zip(r, fmts, strict=True)) + " |")
    return "\n".join(lines)


def html_table(header: Sequence[str], rows: Sequence[Sequence[Any]],
               fmts: Sequence[str] | None = None) -> str:
    """An HTML table, every cell escaped."""
    fmts = list(fmts or [".4g"] * len(header))
    th = "".join(f"<th>{html.escape(str(h))}</th>" for h in header)
    body = "".join("<tr>" + "".join(f"<td>{html.escape(fmt(v, f))}</td>"
                                    for v, f in zip(r, fmts, strict=True)) + "</tr>"
                   for r in rows)
    return f"<table><thead><tr>{th}</tr></thead><tbody>{body}</tbody></table>"


def markdown_to_html_table(md: str) -> str:
    """The HTML form of a Markdown table made by :func:`markdown_table` (cells already text)."""
    lines = [ln for ln in md.splitlines() if ln.startswith("|")]
    head = [c.strip() for c in lines[0].strip("|").split("|")]
    rows = [[c.strip() for c in ln.strip("|").split("|")] for ln in lines[2:]]
    return html_table(head, rows, ["s"] * len(head))


def html_figure(path: Path, caption: str) -> str:
    """A figure with the PNG at ``path`` embedded (the report stays one file); empty if the
    picture was not drawn."""
    path = Path(path)
    if not path.exists():
        return ""
    data = base64.b64encode(path.read_bytes()).decode("ascii")
    cap = html.escape(caption)
    return (f'<figure><img alt="{cap}" src="data:image/png;base64,{data}">'
            f"<figcaption>{cap}</figcaption></figure>")


def html_page(title: str, body: Sequence[str], css: str = CSS) -> str:
    """A complete, self-contained HTML document."""
    return "\n".join(["<!doctype html><html><head><meta charset='utf-8'>",
                      f"<title>{html.escape(title)}</title>", f"<style>{css}</style></head><body>",
                      *body, "</body></html>\n"])
