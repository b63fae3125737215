"""Applying the rules' fixes: in place (``--fix``), as a patch (``--diff``) or
as overrides in a separate layer (``--fix-to``).

- :func:`fix_files`: the entry point, file by file;
- :mod:`.session`: one stage's lint-fix-verify loop;
- :mod:`.sources`: the layers fixes edit, as read and as the fixes left them;
- :mod:`.text_edits`: a fix's change written into a text layer's own text;
- :mod:`.overlay`: ``--fix-to``, the fixes as overrides in a new root layer;
- :mod:`usdrender_lint.layers.writing`: safe writes (unchanged since read, owner kept, atomic);
- :mod:`.diff`: the patch ``--diff`` prints.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

from ..engine import Linter
from ..model import Finding
from .overlay import fix_to
from .session import FixError, FixOptions, FixRun, StageFixer


def fix_files(
    linter: Linter,
    files: Sequence[str],
    options: FixOptions,
    keep: Callable[[Finding], bool] | None = None,
) -> FixRun:
    """Fix each file's stage in turn (--fix, --diff), or write the one stage's
    fixes into the --fix-to layer. ``keep`` says whether a finding is reported
    at all (per-path ignores): a silenced finding is not fixed."""
    keep = keep or (lambda finding: True)
    if options.fix_to:
        return fix_to(linter, files, options, keep)
    run = FixRun()
    for path in files:
        fixer = StageFixer(linter, path, options, keep)
        fixer.run()
        run.extend(fixer.result)
    if not options.write:
        run.once_per_layer()
    return run


__all__ = ["FixError", "FixOptions", "FixRun", "fix_files"]
