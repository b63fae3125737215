"""The framing picture: one SVG per product, drawn from the JSON document.

The camera aperture (dashed), the image it is conformed to (solid), the data
window (the rendered part green, overscan orange, what a crop leaves out
grey), labelled, beside the product's values as the text view lists them.
Values the linter reports are red, and so is a missing camera or an empty
data window written across the image. Pure text: no pxr, no rich.
"""

from __future__ import annotations

import os
import re
from collections.abc import Iterator
from html import escape
from typing import Any

from .picture import Picture, Rect, picture
from .textview import FLAG, NOT_FINITE, Line, value_lines

MIN_WIDTH = 900
DRAWING = 440  # the drawing's width, in pixels
#: The advance of one character of the 12 px monospace font, about.
CHAR_WIDTH = 7.3
MARGIN = 24
LINE_HEIGHT = 17
COLOURS = {
    None: "#222222",
    "dim": "#6b6b6b",
    "bold": "#111111",
    "yellow": "#9a6700",
    "green": "#1a7f37",
    "cyan": "#0969da",
    FLAG: "#cf222e",
}
FILL = {"image": "#e6e6e6", "rendered": "#b7e1c1", "overscan": "#f5c26b"}


def svg_files(document: dict[str, Any]) -> list[tuple[str, str]]:
    """(file name, SVG text) for every product of every computed file, and for
    a settings without products its own framing; names are unique in the run."""
    files: list[tuple[str, str]] = []
    taken: set[str] = set()
    computed = [f for f in document["files"] if f["status"] == "computed"]
    stems = [_stem(f["file"]) for f in computed]
    for file, stem in zip(computed, stems, strict=True):
        if stems.count(stem) > 1:  # shots/a/shot.usda and shots/b/shot.usda
            stem = _slug(file["file"].rsplit(".", 1)[0].replace("\\", "/").replace("/", "_"))
        for settings in file["settings"]:
            products = settings["products"] or [settings["base"]]
            for product in products:
                parts = [stem, _slug(settings["path"].rsplit("/", 1)[-1])]
                if product["path"]:
                    parts.append(_slug(product["path"].rsplit("/", 1)[-1]))
                name = _unique(".".join(parts), taken)
                files.append((f"{name}.svg", product_svg(file, settings, product)))
    return files


def product_svg(file: dict[str, Any], settings: dict[str, Any], product: dict[str, Any]) -> str:
    pic = picture(product)
    problems = [
        text
        for field, text in (("camera", "no camera"), ("dataWindow", "empty data window"))
        if field in product["flags"]
    ]
    title: list[Line] = [
        [(file["file"], "bold")],
        [("RenderSettings ", "dim"), (settings["path"], "bold")],
    ]
    if product["path"] is not None:
        title.append([("RenderProduct ", "dim"), (product["path"], "bold")])
        title.append([("→ ", "dim"), (product["name"] or "(no productName)", None)])
    else:
        title.append([("no products: the settings' own values", "yellow")])
    values = list(value_lines(product))
    text_x = MARGIN * 2 + DRAWING
    body_top = MARGIN + LINE_HEIGHT * (len(title) + 1)
    box = pic.bounds
    aspect = box.height / box.width if box.width > 0 else 1.0
    drawing_height = DRAWING * min(1.0, max(0.3, aspect)) + 30 + LINE_HEIGHT * 4  # + legend
    height = round(
        max(body_top + drawing_height + MARGIN, body_top + LINE_HEIGHT * len(values) + MARGIN)
    )
    longest = max((sum(len(t) for t, _ in line) for line in values), default=0)
    width = max(MIN_WIDTH, round(text_x + longest * CHAR_WIDTH + MARGIN))
    out = [
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" '
        f'viewBox="0 0 {width} {height}" font-family="Menlo, Consolas, monospace" '
        'font-size="12">',
        f'<rect width="{width}" height="{height}" fill="#ffffff"/>',
    ]
    out.extend(_lines(title, MARGIN, MARGIN + LINE_HEIGHT))
    area = drawing_height - 30 - LINE_HEIGHT * 4
    out.extend(_drawing(pic, problems, product, MARGIN, body_top, area))
    out.extend(_lines(values, text_x, body_top + LINE_HEIGHT))
    out.append("</svg>")
    return "\n".join(out) + "\n"


def _drawing(
    pic: Picture,
    problems: list[str],
    product: dict[str, Any],
    left: float,
    top: float,
    area_height: float,
) -> Iterator[str]:
    """The framing in ``DRAWING`` x ``area_height`` pixels at (left, top), and
    below it a legend that labels each shape with its values."""
    box = pic.bounds
    pad = 0.06 * max(box.width, box.height)
    box = Rect(box.left - pad, box.bottom - pad, box.right + pad, box.top + pad)
    scale = min(DRAWING / box.width, area_height / box.height)
    # Centre the drawing in its area.
    x0 = left + (DRAWING - box.width * scale) / 2
    y0 = top + (area_height - box.height * scale) / 2

    def place(rect: Rect) -> tuple[float, float, float, float]:
        return (
            x0 + (rect.left - box.left) * scale,
            y0 + (box.top - rect.top) * scale,
            rect.width * scale,
            rect.height * scale,
        )

    def rect(r: Rect, **attrs: str) -> str:
        x, y, w, h = place(r)
        extra = " ".join(f'{k.replace("_", "-")}="{escape(v)}"' for k, v in attrs.items())
        return f'<rect x="{x:.2f}" y="{y:.2f}" width="{w:.2f}" height="{h:.2f}" {extra}/>'

    yield rect(pic.image, fill=FILL["image"])
    if pic.data is not None:
        yield rect(pic.data, fill=FILL["overscan"])
        inside = pic.data.clamp(pic.image)
        if inside.width > 0 and inside.height > 0:
            yield rect(inside, fill=FILL["rendered"])
    if pic.camera is not None:
        yield rect(pic.camera, fill="none", stroke=COLOURS["cyan"], stroke_dasharray="6 4")
    outline = COLOURS[FLAG] if problems else COLOURS["bold"]
    yield rect(pic.image, fill="none", stroke=outline, stroke_width="2")
    x, y, w, h = place(pic.image)
    for index, problem in enumerate(problems):
        yield _text(
            x + w / 2,
            y + h / 2 + (index - (len(problems) - 1) / 2) * 22 + 6,
            problem,
            COLOURS[FLAG],
            anchor="middle",
            size=18,
        )
    legend_top = top + area_height + 22
    for index, (swatch, label) in enumerate(_legend(pic, product)):
        ly = legend_top + index * LINE_HEIGHT
        if swatch == "camera":
            yield (
                f'<line x1="{left}" y1="{ly - 4}" x2="{left + 12}" y2="{ly - 4}" '
                f'stroke="{COLOURS["cyan"]}" stroke-width="2" stroke-dasharray="4 2"/>'
            )
        else:
            yield f'<rect x="{left}" y="{ly - 10}" width="12" height="12" fill="{FILL[swatch]}"/>'
        yield _text(left + 20, ly, label, COLOURS[None])


def _legend(pic: Picture, product: dict[str, Any]) -> list[tuple[str, str]]:
    """(swatch, label) for each shape drawn."""
    width, height = product["resolution"]
    aperture = product["aperture"]
    image = f"image {width} x {height}"
    if aperture is not None:
        image += f" = the conformed aperture {_pair(aperture['conformed'])}"
    entries = [("image", image)]
    window = product["dataWindow"]
    if pic.data is not None and window is not None:
        kinds = [k for k, on in (("crop", pic.cropped), ("overscan", pic.overscan)) if on]
        label = f"rendered: data window {window['width']} x {window['height']} pixels"
        entries.append(("rendered", label + (f" ({', '.join(kinds)})" if kinds else "")))
        if pic.overscan:
            entries.append(("overscan", "overscan: rendered outside the image"))
    if pic.camera is not None and aperture is not None:
        entries.append(("camera", f"camera aperture {_pair(aperture['camera'])}"))
    return entries


def _pair(values: list[Any]) -> str:
    return " x ".join(f"{v:.6g}" if v is not None else NOT_FINITE for v in values)


def _lines(lines: list[Line], x: float, y: float) -> Iterator[str]:
    for index, line in enumerate(lines):
        spans = "".join(_span(text, style) for text, style in line if text)
        if spans:
            yield (
                f'<text x="{x}" y="{y + index * LINE_HEIGHT}" xml:space="preserve">{spans}</text>'
            )


def _span(text: str, style: str | None) -> str:
    weight = ' font-weight="bold"' if style in ("bold", FLAG) else ""
    colour = COLOURS.get(style, COLOURS[None])
    return f'<tspan fill="{colour}"{weight}>{escape(text, quote=False)}</tspan>'


def _text(x: float, y: float, text: str, colour: str, anchor: str = "start", size: int = 12) -> str:
    return (
        f'<text x="{x:.2f}" y="{y:.2f}" fill="{colour}" font-size="{size}" '
        f'text-anchor="{anchor}">{escape(text, quote=False)}</text>'
    )


def _stem(file: str) -> str:
    # The folder separators of this system only: the name is escaped for
    # printing (a control character is written \x07), and on POSIX a
    # backslash is part of a file's name, not a folder's end.
    return _slug(re.split(_SEPARATORS, file)[-1].rsplit(".", 1)[0])


_SEPARATORS = "[" + re.escape(os.sep + (os.altsep or "")) + "]"


def _slug(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", text).strip("._") or "_"


def _unique(name: str, taken: set[str]) -> str:
    candidate, count = name, 1
    while candidate in taken:
        count += 1
        candidate = f"{name}-{count}"
    taken.add(candidate)
    return candidate
