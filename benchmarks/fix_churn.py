"""Measure how much of a file ``--fix`` changes, on a copy of the shared corpus.

The figures of issue 14 ("fixes a reviewer can accept"), on a copy of
``../shared/corpus`` (the original is never written):

- fixes applied, and the files they are in;
- lines changed: per file, the unified diff's changed blocks, a replaced block
  counting its longer side; and lines per fix (the aim: 1.5 or fewer);
- moved lines (a removed line that comes back verbatim elsewhere) and
  reformatted lines (one that comes back changed only in spacing, number or
  boolean spelling): the fixes' own edits are neither, so both should be 0;
- comment lines lost (the header line's comment included) and fixes refused
  because of comments: both should be 0;
- whether ``git apply --check`` and ``patch -p1 --dry-run`` accept the whole
  corpus's ``--diff``, and whether its exit status says fixes are pending;
- whether a second ``--fix`` changes any byte (it must not);
- with ``--fix-to``: on how many root files the ``--fix-to`` layer composes
  exactly like the ``--fix`` result (``fixing.overlay.composed_stage``).

    .venv/bin/python benchmarks/fix_churn.py                  # safe fixes
    .venv/bin/python benchmarks/fix_churn.py --unsafe-fixes   # and unsafe ones
    .venv/bin/python benchmarks/fix_churn.py --fix-to          # also compare --fix-to
"""

from __future__ import annotations

import argparse
import difflib
import json
import re
import shutil
import subprocess
import sys
import tempfile
from collections import Counter
from pathlib import Path

HERE = Path(__file__).resolve().parent
CORPUS = HERE.parent.parent / "shared" / "corpus"
PYTHON = sys.executable
_SCRIPT = Path(PYTHON).with_name("usdrender-lint")
LINT = [str(_SCRIPT)] if _SCRIPT.exists() else [PYTHON, "-m", "usdrender_lint"]
LAYERS = (".usda", ".usd", ".usdc")
_NUMBER = re.compile(r"(?<![\w.])-?\d+(?:\.\d*)?(?:[eE][-+]?\d+)?(?![\w.])")


def check(cwd: Path, *args: str) -> tuple[int, dict, str, str]:
    """Run ``check`` from ``cwd``; the exit status, the JSON report, stdout, stderr."""
    report = cwd / ".report.json"
    command = [*LINT, "check", "--isolated", "--format", "json", "--output", str(report), *args]
    result = subprocess.run(command, cwd=cwd, capture_output=True, text=True, check=False)
    document = json.loads(report.read_text(encoding="utf-8")) if report.exists() else {}
    report.unlink(missing_ok=True)
    return result.returncode, document, result.stdout, result.stderr


def snapshot(root: Path) -> dict[str, bytes]:
    return {str(p.relative_to(root)): p.read_bytes() for p in root.rglob("*") if p.is_file()}


def lines(data: bytes) -> list[str]:
    return data.decode("utf-8", errors="replace").split("\n")


def normal(line: str) -> str:
    """A line without what a reformat changes: spacing, number and bool spelling."""
    line = _NUMBER.sub(lambda m: repr(float(m.group())), line)
    line = re.sub(r"\btrue\b", "1.0", re.sub(r"\bfalse\b", "0.0", line))
    return "".join(line.split())


def comments(text: str) -> Counter:
    """Every comment's text (the header line's too)."""
    from usdrender_lint.layers.usda_text import comment_lines

    found: Counter = Counter()
    all_lines = text.split("\n")
    for number in comment_lines(text):
        found[all_lines[number - 1].strip()] += 1
    if " " in all_lines[0].strip() and "#" in all_lines[0][1:]:
        found["header: " + all_lines[0]] += 1
    return found


def churn(before: bytes, after: bytes) -> dict[str, int]:
    old, new = lines(before), lines(after)
    changed = 0
    removed: list[str] = []
    added: list[str] = []
    for op, i1, i2, j1, j2 in difflib.SequenceMatcher(None, old, new, autojunk=False).get_opcodes():
        if op == "equal":
            continue
        changed += max(i2 - i1, j2 - j1)
        removed += old[i1:i2]
        added += new[j1:j2]
    moved = sum((Counter(removed) & Counter(added)).values())
    same_after_normalising = Counter(map(normal, removed)) & Counter(map(normal, added))
    reformatted = sum(same_after_normalising.values()) - moved
    text_before, text_after = (data.decode("utf-8", errors="replace") for data in (before, after))
    lost = sum((comments(text_before) - comments(text_after)).values())
    return {"changed": changed, "moved": moved, "reformatted": reformatted, "comments lost": lost}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--corpus", type=Path, default=CORPUS, help="the corpus folder")
    parser.add_argument("--unsafe-fixes", action="store_true", help="measure unsafe fixes too")
    parser.add_argument("--fix-to", action="store_true", help="compare --fix-to with --fix")
    parser.add_argument("--keep", type=Path, help="work here (kept) instead of a temporary dir")
    options = parser.parse_args(argv)
    if not (options.corpus / "files").is_dir():
        print(f"no corpus at {options.corpus}", file=sys.stderr)
        return 2
    work = options.keep or Path(tempfile.mkdtemp(prefix="fix-churn-"))
    try:
        return measure(options, work)
    finally:
        if options.keep is None:
            shutil.rmtree(work, ignore_errors=True)


def measure(options: argparse.Namespace, work: Path) -> int:
    copy = work / "corpus"
    shutil.rmtree(copy, ignore_errors=True)
    shutil.copytree(options.corpus / "files", copy / "files")
    for path in copy.rglob("*"):
        path.chmod(path.stat().st_mode | 0o200)  # the corpus is read-only
    extra = ["--unsafe-fixes"] if options.unsafe_fixes else []
    original = snapshot(copy)

    status, document, patch, _ = check(copy, "--diff", *extra, "files")
    pending = sum(fix["applied"] for fix in document.get("fixes", []))
    (work / "corpus.patch").write_text(patch, encoding="utf-8")
    git = subprocess.run(
        ["git", "apply", "--check", str(work / "corpus.patch")], cwd=copy, capture_output=True
    )
    gnu = subprocess.run(
        ["patch", "-p1", "--dry-run", "-s", "-i", str(work / "corpus.patch")],
        cwd=copy,
        capture_output=True,
    )

    _, document, _, _ = check(copy, "--fix", *extra, "files")
    fixes = document.get("fixes", [])
    applied = [fix for fix in fixes if fix["applied"]]
    refused = Counter(fix["reason"] for fix in fixes if not fix["applied"])
    fixed = snapshot(copy)
    totals: Counter = Counter()
    changed_files = [name for name in original if fixed.get(name) != original[name]]
    for name in changed_files:
        if Path(name).suffix in (".usda", ".usd") and not fixed[name].startswith(b"PXR-USDC"):
            totals.update(churn(original[name], fixed[name]))

    _, again_document, _, _ = check(copy, "--fix", *extra, "files")
    again = snapshot(copy)
    second = [name for name in fixed if again.get(name) != fixed[name]]
    second_applied = sum(fix["applied"] for fix in again_document.get("fixes", []))

    print(f"corpus: {options.corpus} ({'safe and unsafe' if extra else 'safe'} fixes)")
    print(f"fixes applied:                  {len(applied)} in {len(changed_files)} files")
    print(f"lines changed:                  {totals['changed']}")
    per_fix = totals["changed"] / len(applied) if applied else 0.0
    print(f"lines per fix:                  {per_fix:.2f}")
    print(f"moved lines:                    {totals['moved']}")
    print(f"reformatted lines:              {totals['reformatted']}")
    print(f"comment lines lost:             {totals['comments lost']}")
    by_comments = sum(n for reason, n in refused.items() if "comment" in reason)
    print(f"fixes refused for comments:     {by_comments}")
    print(f"fixes not applied:              {sum(refused.values())}")
    for reason, count in refused.most_common():
        print(f"    {count:4}  {reason[:150]}")
    print(f"--diff: fixes pending:          {pending} (exit status {status})")
    print(f"--diff: git apply --check:      {'ok' if git.returncode == 0 else 'FAILED'}")
    print(f"--diff: patch -p1 --dry-run:    {'ok' if gnu.returncode == 0 else 'FAILED'}")
    for tool in (git, gnu):
        if tool.returncode:
            print("    " + (tool.stderr or tool.stdout).decode(errors="replace")[:500])
    print(f"second --fix: files changed:    {len(second)}, fixes applied: {second_applied}")
    if options.fix_to:
        compare_fix_to(options, work, extra)
    return 0


def compare_fix_to(options: argparse.Namespace, work: Path, extra: list[str]) -> None:
    """Per root file, on a fresh copy: --fix-to, then --fix (undone afterwards);
    does the --fix-to layer compose exactly like the fixed file?"""
    from pxr import Sdf, Tf, Usd

    from usdrender_lint.fixing.overlay import composed_stage

    fresh = work / "overlay"
    shutil.rmtree(fresh, ignore_errors=True)
    shutil.copytree(options.corpus / "files", fresh / "files")
    for path in fresh.rglob("*"):
        path.chmod(path.stat().st_mode | 0o200)
    pristine = snapshot(fresh)
    same, different, refused = 0, [], Counter[str]()
    roots = sorted(p for p in fresh.rglob("*") if p.suffix in LAYERS)
    for path in roots:
        overlay = path.with_name(path.stem + ".fixed-overlay.usda")
        _, document, _, _ = check(fresh, "--fix-to", str(overlay), *extra, str(path))
        refused.update(f["reason"] for f in document.get("fixes", []) if not f["applied"])
        if not overlay.exists():
            continue
        with Tf.DiagnosticTrap() as trap:  # the corpus's missing assets: USD's warnings
            overlaid = composed_stage(Usd.Stage.Open(str(overlay)))
            overlay.unlink()
            check(fresh, "--fix", *extra, str(path))
            fixed = composed_stage(Usd.Stage.Open(str(path)))
            trap.Clear()
        for name, data in snapshot(fresh).items():
            if pristine.get(name) != data:
                (fresh / name).write_bytes(pristine[name])
                layer = Sdf.Layer.Find(str(fresh / name))
                if layer is not None:
                    layer.Reload(True)
        if overlaid == fixed:
            same += 1
        else:
            different.append(str(path.relative_to(fresh)))
    print(f"--fix-to: overlays written:     {same + len(different)} of {len(roots)} files")
    print(f"--fix-to: composed as --fix:    {same} (different: {len(different)})")
    for name in different[:10]:
        print(f"    {name}")
    for reason, count in refused.most_common():
        print(f"    refused {count:4}  {reason[:150]}")


if __name__ == "__main__":
    sys.exit(main())
