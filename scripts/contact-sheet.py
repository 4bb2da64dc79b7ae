#!/usr/bin/env python3
"""Draws the SVGs of a `shapecue lines --views/--cameras --out DIR` run as
one contact sheet (a PNG grid, each view labelled with its number), for the
docs. Needs Pillow (`pip install pillow`); it draws shapecue's own SVG
groups (polylines with a stroke colour and width), not SVG in general.

    python3 scripts/contact-sheet.py DIR sheet.png [--columns 4] [--cell 240]
"""

import argparse
import glob
import os
import re

from PIL import Image, ImageDraw

GROUP = re.compile(
    r'<g id="([^"]+)"[^>]*stroke="(#[0-9a-f]{6})" stroke-width="([\d.]+)"[^>]*>(.*?)</g>', re.S
)
LINE = re.compile(r'points="([^"]+)"(?: stroke-opacity="([\d.]+)")?')


def render(path, size, scale=2):
    s = open(path, encoding="utf-8").read()
    w, h = map(int, re.search(r'width="(\d+)" height="(\d+)"', s).groups())
    im = Image.new("RGB", (w * scale, h * scale), "white")
    d = ImageDraw.Draw(im)
    for g in GROUP.finditer(s):
        col, sw, body = g.group(2), float(g.group(3)), g.group(4)
        for pl in LINE.finditer(body):
            pts = [tuple(float(c) * scale for c in p.split(",")) for p in pl.group(1).split()]
            op = float(pl.group(2) or 1)
            c = tuple(int(int(col[i : i + 2], 16) * op + 255 * (1 - op)) for i in (1, 3, 5))
            if len(pts) >= 2:
                d.line(pts, fill=c, width=max(1, round(sw * scale)), joint="curve")
    im.thumbnail((size, size), Image.LANCZOS)
    return im


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("dir")
    ap.add_argument("out")
    ap.add_argument("--columns", type=int, default=4)
    ap.add_argument("--cell", type=int, default=240)
    a = ap.parse_args()
    svgs = sorted(glob.glob(os.path.join(a.dir, "*.svg")))
    if not svgs:
        raise SystemExit(f"{a.dir}: no SVG")
    rows = (len(svgs) + a.columns - 1) // a.columns
    sheet = Image.new("RGB", (a.columns * a.cell, rows * a.cell), "white")
    d = ImageDraw.Draw(sheet)
    for i, p in enumerate(svgs):
        im = render(p, a.cell)
        x, y = (i % a.columns) * a.cell, (i // a.columns) * a.cell
        sheet.paste(im, (x + (a.cell - im.width) // 2, y + (a.cell - im.height) // 2))
        view = re.search(r"_v(\d+)\.svg$", p)
        d.text((x + 6, y + 4), f"view {int(view.group(1)) if view else i}", fill="black")
    sheet.save(a.out)


if __name__ == "__main__":
    main()
