"""The terminal view of the JSON document, as styled lines: per product, the
framing drawn in characters beside its values; values the linter reports are
flagged in red with the finding codes (an empty data window, a missing camera)."""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Iterator, Sequence
from typing import Any

from ..paths import columns
from .picture import Picture, Rect, picture

#: A line is a list of (text, rich style or None) segments (what the text
#: formatter's ``write_lines`` prints: styled on a terminal, plain otherwise).
Line = list[tuple[str, str | None]]

#: The drawing's size in characters (a character is about twice as tall as wide).
COLUMNS, MAX_ROWS, MIN_ROWS = 30, 13, 5
GAP = "   "
FLAG = "bold red"
LEGEND = ("─ image   · camera aperture", "░ rendered  ▒ overscan")


def document_lines(document: dict[str, Any], width: int | None = None) -> Iterator[Line]:
    """``width``: the terminal's columns (None: piped, no limit)."""
    for index, file in enumerate(document["files"]):
        if index:
            yield []
        yield from file_lines(file, width)


def file_lines(file: dict[str, Any], width: int | None = None) -> Iterator[Line]:
    if file["status"] != "computed":
        yield [(file["file"], "bold")]
        yield [("  ", None), ("error", FLAG), (f"  {file['error']}", None)]
        return
    when = {
        "--time": "--time",
        "startTimeCode": "the stage's startTimeCode",
        "default": "no startTimeCode",
    }[file["timeFrom"]]
    yield [(file["file"], "bold"), (f"  at {_time(file['time'])} ({when})", "dim")]
    if not file["settings"]:
        yield [("  no usable RenderSettings", "yellow")]
    # The findings on no settings or product (the stage, a layer, a prim no
    # settings renders) are the file's too: the JSON lists them, so does this view.
    elsewhere = _unplaced(file)
    if elsewhere:
        yield [
            ("  findings elsewhere in the file: ", None),
            (", ".join(elsewhere), FLAG),
            ("  (check lists them)", "dim"),
        ]
    for settings in file["settings"]:
        yield []
        yield from settings_lines(settings, width)


def _unplaced(file: dict[str, Any]) -> list[str]:
    """The codes of the file's findings that no settings or product lists."""
    placed: set[str] = set()
    for settings in file["settings"]:
        placed.update(settings["findings"], settings["base"]["findings"])
        for product in settings["products"]:
            placed.update(product["findings"])
    return [code for code in file["findings"] if code not in placed]


def settings_lines(settings: dict[str, Any], width: int | None = None) -> Iterator[Line]:
    marks = ["primary"] if settings["primary"] else []
    marks.append(f"profile {settings['profile']}")
    yield [
        ("RenderSettings ", None),
        (settings["path"], "bold"),
        (f"  ({', '.join(marks)})", "dim"),
    ]
    purposes = ", ".join(settings["includedPurposes"]) or "none"
    bindings = ", ".join(p or '""' for p in settings["materialBindingPurposes"]) or "none"
    color = settings["renderingColorSpace"] or "the renderer's default"
    yield [(f"  purposes {purposes} · material bindings {bindings} · colour space {color}", None)]
    if settings["findings"]:
        yield [("  findings on the settings: ", None), (", ".join(settings["findings"]), FLAG)]
    if not settings["products"]:
        yield [
            ("  no products: ", "yellow"),
            ("the application decides the outputs; the settings' own values:", None),
        ]
        yield from product_lines(settings["base"], width)
    for product in settings["products"]:
        yield []
        yield from product_lines(product, width)


def product_lines(product: dict[str, Any], width: int | None = None) -> Iterator[Line]:
    if product["path"] is not None:
        yield [
            ("  RenderProduct ", None),
            (product["path"], "bold"),
            (f"  → {product['name'] or '(no productName)'}  ({product['type']})", None),
        ]
    problems = [
        text
        for field, text in (("camera", "no camera"), ("dataWindow", "empty data window"))
        if field in product["flags"]
    ]
    drawing = draw(picture(product), problems)
    values = list(value_lines(product))
    drawn = sum(len(text) for text, _ in drawing[0]) if drawing else 0
    widest = max((columns("".join(text for text, _ in line)) for line in values), default=0)
    if width is not None and 2 + drawn + len(GAP) + widest > width:
        # Side by side, the terminal would wrap every row through the drawing:
        # the values go under it instead.
        yield from ([("  ", None), *line] for line in [*drawing, *values])
        return
    for row in range(max(len(drawing), len(values))):
        left: Line = drawing[row] if row < len(drawing) else [(" " * drawn, None)]
        right = values[row] if row < len(values) else []
        yield [("  ", None), *left, (GAP, None), *right]


def value_lines(product: dict[str, Any]) -> Iterator[Line]:
    row = functools.partial(_row, product["flags"])
    sources = product["sources"]
    runtime = product["cameraAtRunTime"]
    camera = product["camera"] or "none"
    if runtime is not None:
        camera += f"  (created at run time: {runtime['profile']} profile)"
    yield row("camera", camera, note=_source(sources.get("camera")))
    times = _rendered_times(product["renderedTimes"])
    if runtime is not None:
        times = "the camera's values are the application's, not in the file"
    yield row("time", _time(product["time"]), note=times)
    width, height = product["resolution"]
    yield row("resolution", f"{width} x {height}", note=_source(sources.get("resolution")))
    yield row(
        "pixel aspect",
        _num(product["pixelAspectRatio"]),
        "pixelAspectRatio",
        _source(sources.get("pixelAspectRatio")),
    )
    yield from _conform_lines(product, row)
    yield from _data_window_lines(product, row)
    shutter = product["shutter"]
    blur = "off" if product["disableMotionBlur"] else "on"
    if shutter is not None:
        blur += f", shutter {_num(shutter[0])} .. {_num(shutter[1])}"
    yield row("motion blur", blur, "disableMotionBlur")
    yield row("depth of field", "off" if product["disableDepthOfField"] else "on")
    for index, var in enumerate(product["vars"]):
        yield row(
            "vars" if index == 0 else "",
            f"{var['name']}  {_quoted(var['sourceName'])} {var['sourceType']} {var['dataType']}",
        )
    if product["path"] is not None and not product["vars"]:
        yield row("vars", "none")
    yield from _compute_spec_lines(product)
    if product["findings"]:
        yield row("findings", ", ".join(product["findings"]))


#: ``_row`` with the product's flags bound: (label, text, field, note) -> a line.
_Row = Callable[..., Line]


def _row(
    flags: dict[str, list[str]], label: str, text: str, field: str | None = None, note: str = ""
) -> Line:
    """A labelled value, in the flag colour with the flags' reasons when ``field``
    (by default the label) is flagged, then a dim ``note``."""
    flagged = flags.get(field or label, [])
    line: Line = [(f"{label:<15}", "dim"), (text, FLAG if flagged else None)]
    if flagged:
        line.append((f"  [{'; '.join(flagged)}]", FLAG))
    if note:
        line.append((f"  {note}", "dim"))
    return line


def _rendered_times(times: list) -> str:
    if not times:
        return "no camera"
    if times == ["default"]:
        return "camera not animated"
    rendered = "rendered times " + ", ".join(_time(t) for t in times[:6])
    if len(times) > 6:
        rendered += f", … ({len(times)})"
    return rendered


def _conform_lines(product: dict[str, Any], row: _Row) -> Iterator[Line]:
    """The conform policy and what it does to the camera's aperture."""
    aperture = product["aperture"]
    policy = product["aspectRatioConformPolicy"]
    if aperture is None:
        note = "no camera aperture to conform"
        if product["cameraAtRunTime"] is not None:
            note = "conforms the run-time camera's aperture"
        yield row("conform", policy, "aspectRatioConformPolicy", note)
        return
    yield row("conform", policy, "aspectRatioConformPolicy", _adjusted(aperture))
    yield row(
        "aperture",
        f"{_pair(aperture['camera'])} → {_pair(aperture['conformed'])}",
        note=f"offset {_pair(aperture['offset'], ', ')}",
    )
    window = product["screenWindow"]
    yield row("screen window", " ".join(_num(c, 4) for c in window), note=product["projection"])


def _adjusted(aperture: dict[str, Any]) -> str:
    changed = aperture["adjusted"]
    if changed in ("width", "height"):
        return f"adjusts the {changed}"
    if changed == "pixelAspectRatio":
        return "adjusts the pixel aspect ratio"
    return aperture["notConformed"] or "nothing to adjust"


def _data_window_lines(product: dict[str, Any], row: _Row) -> Iterator[Line]:
    ndc = product["dataWindowNDC"]
    pixels = product["dataWindow"]
    ndc_text = "(" + ", ".join(_num(c) for c in ndc) + ")"
    if pixels is None:
        width, height = product["resolution"]
        why = (
            "no pixels at this resolution" if width <= 0 or height <= 0 else "a bound is not finite"
        )
        yield row("data window", ndc_text, "dataWindow", why)
        return
    (x0, x1), (y0, y1) = pixels["x"], pixels["y"]
    yield row(
        "data window",
        f"x {x0}..{x1}, y {y0}..{y1}  ({pixels['width']} x {pixels['height']})",
        "dataWindow",
    )
    sources = product["sources"]
    yield row("", f"NDC {ndc_text}", "dataWindowNDC", _source(sources.get("dataWindowNDC")))


def _compute_spec_lines(product: dict[str, Any]) -> Iterator[Line]:
    """Where UsdRenderComputeSpec would give another answer."""
    compute = product["usdRenderComputeSpec"]
    if not compute["included"] and product["path"] is not None:
        yield [(f"{'ComputeSpec':<15}", "dim"), (compute["reason"], "yellow")]
    elif compute["differs"]:
        differs = "; ".join(f"{k} {_value(v)}" for k, v in compute["differs"].items())
        yield [(f"{'ComputeSpec':<15}", "dim"), (f"reads Default: {differs}", "yellow")]


# -- the drawing --------------------------------------------------------------------


def draw(pic: Picture, problems: Sequence[str] = ()) -> list[Line]:
    """The framing in characters: rows of styled segments, all one width;
    ``problems`` (no camera, an empty data window) are written inside in red."""
    box = pic.bounds
    aspect = box.height / box.width if box.width > 0 else 1.0
    rows = min(MAX_ROWS, max(MIN_ROWS, round(COLUMNS * aspect / 2)))
    columns = COLUMNS if rows < MAX_ROWS else max(8, min(COLUMNS, round(rows * 2 / aspect)))
    blank: tuple[str, str | None] = (" ", None)
    grid = [[blank] * columns for _ in range(rows)]
    cells = _Cells(box, columns, rows)
    image = cells.span(pic.image)
    if pic.data is not None:
        _fill_data_window(grid, image, cells.span(pic.data))
    if pic.camera is not None:
        _outline(grid, cells.span(pic.camera), {"h": "·", "v": "·", "corner": "·"}, "cyan")
    _outline(grid, image, _BOX, FLAG if problems else "bold")
    _write_problems(grid, image, problems)
    # A tall picture is narrower: pad it, so that the legend stays whole and
    # the values of every product start in one column.
    width = max(COLUMNS, *(len(text) for text in LEGEND))
    pad: Line = [(" " * (width - columns), None)] if width > columns else []
    lines: list[Line] = [_merge(r) + pad for r in grid]
    lines.extend([(text.ljust(width), "dim")] for text in LEGEND)
    return lines


def _fill_data_window(
    grid: list[Line], image: tuple[int, int, int, int], data: tuple[int, int, int, int]
) -> None:
    """The data window's cells: green inside the image, yellow outside (overscan)."""
    c0, r0, c1, r1 = data
    for r in range(r0, r1 + 1):
        for c in range(c0, c1 + 1):
            inside = image[0] <= c <= image[2] and image[1] <= r <= image[3]
            grid[r][c] = ("░", "green") if inside else ("▒", "yellow")


def _write_problems(
    grid: list[Line], image: tuple[int, int, int, int], problems: Sequence[str]
) -> None:
    """``problems`` centred inside the image's outline, as many as fit."""
    inner = max(1, image[2] - image[0] - 1)
    first = (image[1] + image[3] - len(problems) + 1) // 2
    for row, problem in enumerate(problems, start=max(image[1] + 1, first)):
        if row >= image[3]:
            break
        text = problem[:inner]
        start = image[0] + 1 + (inner - len(text)) // 2
        for offset, char in enumerate(text):
            grid[row][start + offset] = (char, FLAG)


_BOX = {"h": "─", "v": "│", "tl": "┌", "tr": "┐", "bl": "└", "br": "┘"}


class _Cells:
    """Maps aperture coordinates (y up) to character cells (row 0 at the top)."""

    def __init__(self, box: Rect, columns: int, rows: int) -> None:
        self.box, self.columns, self.rows = box, columns, rows

    def span(self, rect: Rect) -> tuple[int, int, int, int]:
        """(first column, first row, last column, last row) of a rectangle."""
        box = self.box

        def column(x: float) -> int:
            t = (x - box.left) / box.width if box.width else 0.5
            return min(self.columns - 1, max(0, round(t * (self.columns - 1))))

        def row(y: float) -> int:
            t = (box.top - y) / box.height if box.height else 0.5
            return min(self.rows - 1, max(0, round(t * (self.rows - 1))))

        return column(rect.left), row(rect.top), column(rect.right), row(rect.bottom)


def _outline(grid: list, span: tuple[int, int, int, int], chars: dict, style: str) -> None:
    c0, r0, c1, r1 = span
    corner = chars.get("corner")
    for c in range(c0, c1 + 1):
        grid[r0][c] = (chars["h"], style)
        grid[r1][c] = (chars["h"], style)
    for r in range(r0, r1 + 1):
        grid[r][c0] = (chars["v"], style)
        grid[r][c1] = (chars["v"], style)
    for r, c, key in ((r0, c0, "tl"), (r0, c1, "tr"), (r1, c0, "bl"), (r1, c1, "br")):
        grid[r][c] = (corner or chars[key], style)


def _merge(cells: list[tuple[str, str | None]]) -> Line:
    """Adjacent cells of one style as one segment."""
    line: Line = []
    for char, style in cells:
        if line and line[-1][1] == style:
            line[-1] = (line[-1][0] + char, style)
        else:
            line.append((char, style))
    return line


# -- numbers -------------------------------------------------------------------------


def _time(time: Any) -> str:
    return "Default" if time == "default" else _num(time)


#: How a number the document holds as null (NaN or infinite) is shown.
NOT_FINITE = "not finite"


def _num(value: Any, digits: int = 6) -> str:
    if value is None:  # the JSON document's null: NaN and infinities alike
        return NOT_FINITE
    if isinstance(value, float) and not math.isfinite(value):
        return str(value)
    return f"{value:.{digits}g}"


def _pair(values: list[Any], sep: str = " x ") -> str:
    return sep.join(_num(v) for v in values)


def _value(value: Any) -> str:
    if isinstance(value, list):
        return _pair(value)
    if isinstance(value, str):
        return _quoted(value)
    return _num(value)


def _quoted(text: str) -> str:
    """A string value in quotes, so that an empty one shows. Not ``repr``: the
    document's strings are escaped for printing already (``\\x1b``), and
    ``repr`` would double their backslashes, showing a control character as
    four characters of text."""
    return f"'{text}'"


def _source(source: dict[str, Any] | None) -> str:
    if source is None:
        return ""
    if source["from"] == "fallback":
        return "fallback"
    where = source["layer"] or ""
    if where and source["line"]:
        where += f":{source['line']}"
    return f"{source['from']}, {where}" if where else source["from"]
