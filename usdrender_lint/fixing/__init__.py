"""Applying the rules' fixes: in place (``--fix``), as a patch (``--diff``) or
as overrides in a separate layer (``--fix-to``)."""
