"""Applying the rules' fixes: in place (``--fix``), as a patch (``--diff``) or
as overrides in a separate layer (``--fix-to``).

- :mod:`.session`: one stage's lint-fix-verify loop, and the entry point
  :func:`fix_files`;
- :mod:`.sources`: the layers fixes edit, as read and as the fixes left them;
- :mod:`.text_edits`: a fix's change written into a text layer's own text;
- :mod:`.overlay`: ``--fix-to``, the fixes as overrides in a new root layer;
- :mod:`.writing`: safe writes (unchanged since read, owner kept, atomic);
- :mod:`.diff`: the patch ``--diff`` prints.
"""

from .session import FixError, FixOptions, FixRun, fix_files

__all__ = ["FixError", "FixOptions", "FixRun", "fix_files"]
