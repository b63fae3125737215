"""``--format html``: one self-contained page for CI artifacts and reviewers.

A summary; per file its findings, each with the source lines around it, the
fix as a diff where there is one, and the renderer profile it was judged
under and why; per RenderSettings and product the framing picture ``spec``
draws (its SVG, inline) with the findings on that product beside it.
Filters by severity, code and profile run in the page's own script, with no
server, and live in the address's ``#`` part (``#severity=error&code=SE003``)
so a filtered view can be linked. No network: styles, script and pictures are
inline, and nothing is fetched.

What the page shows beside the findings is read from the files the report
names (:mod:`usdrender_lint.running.report_views`); a merged report whose
files are not on disk is shown with its findings only, and says so.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Iterable, Sequence
from html import escape as _html_escape
from typing import TYPE_CHECKING, TextIO

from ..model import FileResult, Finding, FixInfo, Report, RuleInfo, Severity
from ..paths import display_path, printable
from ..running.report_views import finding_key as _key
from . import HELD_BY_BASELINE, FormatOptions, shown_fix

if TYPE_CHECKING:
    from ..running.report_views import Excerpt, FileView, ReportViews

SEVERITIES = (Severity.ERROR, Severity.WARNING, Severity.INFO)
#: RenderSettings named on a file's line for a profile and its reason; the
#: rest are counted (each finding names its own).
PROFILE_NAMES = 5


class HtmlFormatter:
    """The report as one HTML page (see the module docstring)."""

    #: It never reads the configuration digest, so the command does not compute it.
    reads_configuration = False

    def render(self, report: Report, stream: TextIO, options: FormatOptions) -> None:
        from ..running.report_views import gather

        page = render_page(report, gather(report, options.settings_of), options)
        try:
            page.encode("utf-8")
        except UnicodeEncodeError:  # a name not UTF-8 inside a picture: never invalid UTF-8
            page = page.encode("utf-8", "surrogateescape").decode("utf-8", "replace")
        stream.write(page)


def render_page(report: Report, views: ReportViews, options: FormatOptions) -> str:
    counts = report.by_severity()
    rules = {rule.code: rule for rule in report.rules}
    findings = report.findings
    safe, unsafe = report.fixable()
    files_with = sum(1 for r in report.files if r.findings)
    out: list[str] = [
        "<!DOCTYPE html>",
        '<html lang="en">',
        "<head>",
        '<meta charset="utf-8">',
        '<meta name="viewport" content="width=device-width, initial-scale=1">',
        # Nothing may be fetched: the page is a CI artifact opened anywhere.
        '<meta http-equiv="Content-Security-Policy" content="default-src \'none\'; '
        "style-src 'unsafe-inline'; script-src 'unsafe-inline'; img-src data:\">",
        f"<title>{escape(options.tool_name)} report</title>",
        f"<style>{_CSS}</style>",
        "</head>",
        "<body>",
        '<header class="top">',
        '<div class="title">',
        f"<h1>{escape(options.tool_name)} report</h1>",
        f'<span class="dim">version {escape(options.tool_version)}</span>',
        "</div>",
        '<div class="summary" id="summary">',
        f'<span class="chip error">{counts["error"]} error{_s(counts["error"])}</span>',
        f'<span class="chip warning">{counts["warning"]} warning{_s(counts["warning"])}</span>',
        f'<span class="chip info">{counts["info"]} info</span>',
        f'<span class="chip">{len(report.files)} file{_s(len(report.files))}, '
        f"{files_with} with findings</span>",
        f'<span class="chip">{safe} fixable with --fix'
        + (f", {unsafe} more unsafe" if unsafe else "")
        + "</span>",
        "</div>",
    ]
    out += _filters(findings, rules)
    out.append("</header>")
    out.append("<main>")
    for note in views.notes:
        out.append(f'<p class="note">{escape(note)}</p>')
    if not report.files:
        out.append('<p class="note">No USD files were linted.</p>')
    for index, result in enumerate(report.files):
        out.extend(_file_section(index, result, views.files.get(result.file), rules, report))
    out.append("</main>")
    out.append(
        '<footer class="dim">Filters live in the address (<code>#severity=error&amp;code=SE003'
        "</code>). Pictures: the framing <code>usdrender-lint spec</code> draws.</footer>"
    )
    out.append(f"<script>{_JS}</script>")
    out.append("</body>")
    out.append("</html>")
    return "\n".join(out) + "\n"


def _filters(findings: Sequence[Finding], rules: dict) -> list[str]:
    """The filter form: severities, the codes and profiles found, clean files."""
    codes = Counter(f.code for f in findings)
    profiles = Counter(f.profile or "none" for f in findings)
    out = [
        '<form class="filters" id="filters" aria-label="Filters">',
        "<fieldset><legend>Severity</legend>",
    ]
    for severity in SEVERITIES:
        out.append(
            f'<label><input type="checkbox" name="severity" value="{severity.value}" checked> '
            f"{severity.value}</label>"
        )
    out.append("</fieldset>")
    out.append('<label>Code <select name="code"><option value="">all codes</option>')
    for code, count in sorted(codes.items()):
        name = rules[code].name if code in rules else _first_name(findings, code)
        out.append(
            f'<option value="{escape(code)}">{escape(code)} {escape(name)} ({count})</option>'
        )
    out.append("</select></label>")
    out.append('<label>Profile <select name="profile"><option value="">all profiles</option>')
    for profile, count in sorted(profiles.items()):
        out.append(f'<option value="{escape(profile)}">{escape(profile)} ({count})</option>')
    out.append("</select></label>")
    out.append(
        '<label><input type="checkbox" name="clean" value="show"> files without findings</label>'
    )
    out.append('<output id="shown" aria-live="polite"></output>')
    out.append("</form>")
    return out


def _file_section(
    index: int, result: FileResult, view: FileView | None, rules: dict, report: Report
) -> list[str]:
    ids = {_key(finding): f"f{index}-{number}" for number, finding in enumerate(result.findings)}
    out = _file_head(index, result)
    if result.error:
        out.append(f'<p class="note error-text">{escape(result.error)}</p>')
    for note in result.notes:
        out.append(f'<p class="note">{escape(note)}</p>')
    if view is not None:
        out += _view_notes(result, view)
    if result.findings:
        out.append('<ol class="findings">')
        for finding in result.findings:
            out.extend(_finding(finding, ids[_key(finding)], view, rules, report))
        out.append("</ol>")
    if view is not None and view.products:
        out += _framing(index, result, view, ids)
    out.append("</details>")
    out.append("</section>")
    return out


def _file_head(index: int, result: FileResult) -> list[str]:
    """The section's opening: the file's path, its counts by severity, and
    whether it was linted (a file with findings or not linted starts open)."""
    shown = display_path(result.file)
    sev = Counter(f.severity.value for f in result.findings)
    badges = "".join(
        f'<span class="chip {s.value}">{sev[s.value]} {s.value}</span>'
        for s in SEVERITIES
        if sev[s.value]
    )
    status = "" if result.status == "linted" else '<span class="chip error">not linted</span>'
    worth_opening = bool(result.findings) or result.status != "linted"
    return [
        f'<section class="file" id="file-{index}" data-findings="{len(result.findings)}">',
        f"<details{' open' if worth_opening else ''}>",
        f'<summary><span class="path">{escape(shown)}</span> {badges}{status}'
        + ("" if worth_opening else '<span class="ok">clean</span>')
        + "</summary>",
    ]


def _view_notes(result: FileResult, view: FileView) -> list[str]:
    """Why a file with findings has no picture, and each RenderSettings' profile."""
    out = []
    # ST001 (the stage does not open) says why already.
    if (
        view.spec_error
        and result.status == "linted"
        and result.findings
        and all(f.code != "ST001" for f in result.findings)
    ):
        out.append(f'<p class="note">No framing picture: {escape(view.spec_error)}</p>')
    # One line per profile and reason: a stage of 1,500 RenderSettings judged
    # alike had 1,500 identical lines above its first finding.
    alike: dict[tuple[str, str], list[str]] = {}
    for settings_path, judged in view.profiles.items():
        alike.setdefault(judged, []).append(settings_path)
    for (profile, reason), paths in alike.items():
        named = ", ".join(f"<code>{escape(path)}</code>" for path in paths[:PROFILE_NAMES])
        if len(paths) > PROFILE_NAMES:
            named = (
                f"{len(paths):,} RenderSettings, {named} and {len(paths) - PROFILE_NAMES:,} more"
            )
        else:
            named = f"RenderSettings {named}"
        out.append(
            f'<p class="profile">{named}: '
            f'profile <b>{escape(profile)}</b> <span class="dim">({escape(reason)})</span></p>'
        )
    return out


def _framing(index: int, result: FileResult, view: FileView, ids: dict) -> list[str]:
    count = len(view.products)
    out = [
        f'<details class="framing" open><summary>Framing: {count} '
        f"picture{_s(count)} (what <code>usdrender-lint spec</code> draws)</summary>",
        '<div class="products">',
    ]
    for number, product in enumerate(view.products):
        out.extend(_product_figure(f"p{index}-{number}", product, result.findings, ids))
    out.append("</div></details>")
    return out


def _product_figure(anchor: str, product, findings: Iterable[Finding], ids: dict) -> list[str]:
    keys = set(product.findings)
    mine = [f for f in findings if _key(f) in keys]
    label = product.product or f"{product.settings} (no products)"
    out = [
        f'<figure class="product" id="{anchor}">',
        f'<div class="picture">{product.svg}</div>',
        f"<figcaption><h3>{escape(label)}</h3>",
    ]
    if mine:
        out.append('<ul class="beside">')
        for finding in mine:
            out.append(
                f'<li {_data(finding)}><a href="#{ids[_key(finding)]}">'
                f'<span class="sev {finding.severity.value}">{finding.severity.value}</span> '
                f"<b>{escape(finding.code)}</b> {escape(finding.message)}</a></li>"
            )
        out.append("</ul>")
    else:
        out.append('<p class="ok">no findings on this product</p>')
    out.append("</figcaption></figure>")
    return out


def _finding(
    finding: Finding, anchor: str, view: FileView | None, rules: dict, report: Report
) -> list[str]:
    out = [f'<li class="finding" id="{anchor}" {_data(finding)}>']
    out += _finding_head(finding, rules.get(finding.code))
    out.append(f'<p class="message">{escape(finding.message)}</p>')
    stated = set(view.profiles.values()) if view is not None else set()
    if finding.profile and (finding.profile, finding.profile_reason) not in stated:
        # Not said on the file's RenderSettings line above: say it here.
        out.append(
            f'<p class="why dim">profile {escape(finding.profile)}: '
            f"{escape(finding.profile_reason or '')}</p>"
        )
    key = _key(finding)
    excerpt = view.excerpts.get(key) if view is not None else None
    if excerpt is not None:
        out.append(_excerpt(excerpt))
    shown = shown_fix(report, finding)
    if shown is not None:
        out += _fix(*shown, view.diffs.get(key) if view is not None else None)
    out.append("</li>")
    return out


def _finding_head(finding: Finding, rule: RuleInfo | None) -> list[str]:
    """Severity, code (the rule's summary on hover), name, where, and profile."""
    loc = finding.location
    where = display_path(loc.layer or loc.file)
    if loc.line is not None:
        where += f":{loc.line}"
    summary = f' title="{escape(rule.summary)}"' if rule is not None and rule.summary else ""
    out = [
        '<div class="head">',
        f'<span class="sev {finding.severity.value}">{finding.severity.value}</span>',
        f'<b class="code"{summary}>{escape(finding.code)}</b>',
        f'<span class="name">{escape(finding.name)}</span>',
        f'<code class="at">{escape(loc.path or "(stage)")}</code>',
        f'<span class="where dim">{escape(where)}</span>',
    ]
    if finding.profile:
        # The reason is on hover here; the file's settings line says it in full.
        out.append(
            f'<span class="chip prof" title="{escape(finding.profile_reason or "")}">'
            f"profile {escape(finding.profile)}</span>"
        )
    out.append("</div>")
    return out


def _fix(fix: FixInfo, held: bool, diff: str | None) -> list[str]:
    kind = "fix" if fix.safe else "unsafe fix (--unsafe-fixes)"
    if held:  # --fix leaves it: marked as the text report marks it, with no diff
        kind = f"{'fix' if fix.safe else 'unsafe fix'}, {HELD_BY_BASELINE}"
        diff = None
    out = [f'<p class="fix"><span class="tag">{kind}</span> {escape(fix.description)}</p>']
    if diff:
        out.append(_diff(diff))
    return out


def _excerpt(excerpt: Excerpt) -> str:
    rows = []
    for offset, text in enumerate(excerpt.lines):
        number = excerpt.first + offset
        mark = ' class="hit"' if number == excerpt.line else ""
        rows.append(f"<span{mark}><i>{number}</i>{_code(text) or ' '}</span>")
    return f'<pre class="source" aria-label="{escape(excerpt.layer)}">' + "".join(rows) + "</pre>"


def _diff(diff: str) -> str:
    rows = []
    for line in diff.splitlines():
        kind = "d-ctx"
        if line.startswith(("+++", "---")):
            kind = "d-name"
        elif line.startswith("@@"):
            kind = "d-hunk"
        elif line.startswith("+"):
            kind = "d-add"
        elif line.startswith("-"):
            kind = "d-del"
        rows.append(f'<span class="{kind}">{_code(line) or " "}</span>')
    return '<pre class="diff">' + "".join(rows) + "</pre>"


def _data(finding: Finding) -> str:
    return (
        f'data-severity="{finding.severity.value}" data-code="{escape(finding.code)}" '
        f'data-profile="{escape(finding.profile or "none")}"'
    )


def escape(text: str) -> str:
    """``text`` (a name, a message) for HTML, as the text report prints it:
    control and bidirectional characters escaped (``\\x1b``, ``\\n``,
    ``\\u202e``), but whole."""
    return _html_escape(printable(text, limit=None))


def _code(line: str) -> str:
    """A line of a layer or a diff for HTML: its controls (tabs kept) escaped
    as :func:`escape` does."""
    return _html_escape(printable(line, keep="\t", limit=None))


def _first_name(findings: Iterable[Finding], code: str) -> str:
    return next((f.name for f in findings if f.code == code), "")


def _s(count: int) -> str:
    return "" if count == 1 else "s"


_CSS = """
:root { --error:#cf222e; --warning:#9a6700; --info:#0969da; --ok:#1a7f37; --line:#d0d7de;
  --dim:#57606a; --bg:#f6f8fa; }
* { box-sizing: border-box; }
body { margin:0; font:14px/1.45 system-ui, -apple-system, "Segoe UI", Roboto, sans-serif;
  color:#1f2328; background:#fff; }
code, pre, .path, .at { font-family: ui-monospace, Menlo, Consolas, monospace; font-size:12.5px; }
.top { position:sticky; top:0; z-index:2; background:#fff; border-bottom:1px solid var(--line);
  padding:8px 20px; display:flex; flex-wrap:wrap; gap:6px 18px; align-items:center; }
.title { display:flex; align-items:baseline; gap:10px; }
h1 { font-size:18px; margin:0; }
.summary { display:flex; flex-wrap:wrap; gap:6px; }
.chip { border:1px solid var(--line); border-radius:12px; padding:1px 9px; background:var(--bg);
  white-space:nowrap; font-size:12.5px; }
.chip.error { color:var(--error); border-color:#ffcecb; background:#ffebe9; }
.chip.warning { color:var(--warning); border-color:#f5e0a0; background:#fff8c5; }
.chip.info { color:var(--info); border-color:#b6e3ff; background:#ddf4ff; }
.filters { display:flex; flex-wrap:wrap; gap:6px 14px; align-items:center; margin-left:auto; }
.filters fieldset { border:0; margin:0; padding:0; display:flex; gap:8px; align-items:center; }
.filters legend { float:left; margin-right:6px; font-weight:600; }
.filters select { max-width:260px; font:inherit; }
#shown { color:var(--dim); font-size:12.5px; }
main { padding:12px 20px 40px; max-width:1600px; }
.file { border:1px solid var(--line); border-radius:6px; margin:10px 0; background:#fff; }
.file > details > summary { cursor:pointer; padding:8px 12px; background:var(--bg);
  border-radius:6px; display:flex; gap:8px; align-items:center; flex-wrap:wrap; }
.file .path { font-weight:600; word-break:break-all; }
.ok { color:var(--ok); }
.note { background:#fff8c5; border:1px solid #f5e0a0; padding:6px 10px; border-radius:6px; }
.error-text { color:var(--error); }
.file > details > :not(summary) { margin-left:12px; margin-right:12px; }
.products { display:grid; gap:12px; margin:10px 12px; }
.framing > summary { cursor:pointer; font-weight:600; margin:6px 0; }
.product { margin:0; display:grid; grid-template-columns:minmax(0,1fr) 290px;
  gap:14px; border:1px solid var(--line); border-radius:6px; padding:8px; }
.product .picture svg { width:100%; height:auto; display:block; }
.product h3 { margin:0 0 6px; font-size:14px; font-family:ui-monospace, Menlo, monospace;
  overflow-wrap:anywhere; }
.beside { list-style:none; margin:0; padding:0; overflow-wrap:anywhere; }
.product figcaption { min-width:0; }
.beside li { margin:0 0 6px; font-size:13px; }
.beside a { color:inherit; text-decoration:none; }
.beside a:hover { text-decoration:underline; }
.findings { list-style:none; padding:0; margin:10px 12px 14px; }
.finding { border-left:4px solid var(--line); padding:6px 10px; margin:8px 0; background:#fff; }
.finding[data-severity=error] { border-left-color:var(--error); }
.finding[data-severity=warning] { border-left-color:#d4a72c; }
.finding[data-severity=info] { border-left-color:var(--info); }
.finding:target { background:#fff8c5; }
.head { display:flex; gap:8px; flex-wrap:wrap; align-items:baseline; }
/* A flex item is as wide as its longest word unless told: paths break anywhere. */
.head > * { min-width:0; overflow-wrap:anywhere; }
.sev { font-size:11px; text-transform:uppercase; font-weight:700; letter-spacing:.03em; }
.sev.error { color:var(--error); } .sev.warning { color:var(--warning); }
.sev.info { color:var(--info); }
.code { font-family:ui-monospace, Menlo, monospace; }
.name, .dim, .where { color:var(--dim); }
.message { margin:4px 0; overflow-wrap:anywhere; }
.profile { margin:4px 0; font-size:13px; }
.why { margin:2px 0; font-size:12px; }
.chip.prof { font-size:11.5px; }
.fix { margin:6px 0 2px; }
.tag { background:#dafbe1; color:var(--ok); border-radius:4px; padding:0 6px; font-size:12px; }
pre { background:var(--bg); border:1px solid var(--line); border-radius:6px; padding:6px 0;
  overflow-x:auto; margin:6px 0; max-width:100%; }
pre > span { display:block; padding:0 10px; white-space:pre; }
pre.source i { display:inline-block; width:3.5em; color:#8c959f; font-style:normal;
  text-align:right; margin-right:12px; user-select:none; }
pre.source .hit { background:#fff8c5; }
pre.diff .d-add { background:#dafbe1; } pre.diff .d-del { background:#ffebe9; }
pre.diff .d-hunk { color:var(--info); } pre.diff .d-name { color:var(--dim); }
footer { padding:10px 20px 24px; font-size:12.5px; }
[hidden] { display:none !important; }
@media (max-width: 1100px) { .product { grid-template-columns:1fr; } }
"""

# The filters: the controls and the address's #... part hold one state; the
# page shows the findings it admits and the files that still have any.
_JS = """
(function () {
  var form = document.getElementById('filters');
  var shown = document.getElementById('shown');
  function state() {
    var sev = [].slice.call(form.querySelectorAll('input[name=severity]:checked'))
      .map(function (i) { return i.value; });
    return { severity: sev, code: form.code.value, profile: form.profile.value,
             clean: form.clean.checked };
  }
  function admits(el, s) {
    return s.severity.indexOf(el.dataset.severity) >= 0 &&
      (!s.code || el.dataset.code === s.code) &&
      (!s.profile || el.dataset.profile === s.profile);
  }
  function apply() {
    var s = state(), total = 0, visible = 0;
    document.querySelectorAll('[data-severity]').forEach(function (el) {
      var ok = admits(el, s);
      el.hidden = !ok;
      if (el.classList.contains('finding')) { total++; if (ok) visible++; }
    });
    var filtering = s.severity.length < 3 || s.code || s.profile;
    document.querySelectorAll('section.file').forEach(function (sec) {
      var any = sec.querySelector('.finding:not([hidden])') !== null;
      var clean = sec.dataset.findings === '0';
      sec.hidden = clean ? !s.clean : (filtering && !any);
    });
    shown.value = 'showing ' + visible + ' of ' + total + ' findings';
    document.body.dataset.visible = String(visible);
    var parts = [];
    if (s.severity.length < 3) parts.push('severity=' + s.severity.join(','));
    if (s.code) parts.push('code=' + encodeURIComponent(s.code));
    if (s.profile) parts.push('profile=' + encodeURIComponent(s.profile));
    if (s.clean) parts.push('clean=show');
    var hash = parts.length ? '#' + parts.join('&') : '';
    var filterHash = /^#(severity|code|profile|clean)=/.test(location.hash);
    if ((parts.length || filterHash) && location.hash !== hash) {
      history.replaceState(null, '', hash || location.pathname + location.search);
    }
  }
  function fromHash() {
    var params = {};
    location.hash.replace(/^#/, '').split('&').forEach(function (pair) {
      var i = pair.indexOf('=');
      if (i > 0) params[pair.slice(0, i)] = decodeURIComponent(pair.slice(i + 1));
    });
    if ('severity' in params) {
      var wanted = params.severity.split(',');
      form.querySelectorAll('input[name=severity]').forEach(function (i) {
        i.checked = wanted.indexOf(i.value) >= 0;
      });
    }
    if ('code' in params) form.code.value = params.code;
    if ('profile' in params) form.profile.value = params.profile;
    form.clean.checked = params.clean === 'show';
  }
  form.addEventListener('change', apply);
  form.addEventListener('submit', function (e) { e.preventDefault(); });
  window.addEventListener('hashchange', function () { fromHash(); apply(); });
  if (/^#(severity|code|profile|clean)=/.test(location.hash)) fromHash();
  apply();
})();
"""

__all__ = ["HtmlFormatter", "render_page"]
