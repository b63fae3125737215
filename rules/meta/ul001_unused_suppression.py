"""UL001 unused-suppression."""

from __future__ import annotations

from usdrender_lint.api import Rule, Severity


class UnusedSuppression(Rule):
    """A customData suppression silences nothing.

    ## What it does
    Reports each entry of a prim's `usdrender_lint:ignore` customData list
    that silenced no finding on that prim or its properties: the rule it names
    ran and found nothing there, or no rule has that code or name. Entries for
    rules that were not selected are left alone (they could not fire). A value
    that is not a list of strings is reported too. The engine emits this
    finding after the other rules ran; listing `UL001` on a prim silences it.

    ## Why is this bad?
    A stale suppression hides the next real problem of that rule on the prim,
    and a misspelt one silences nothing while looking as if it did. Comments
    cannot carry suppressions: USD's text parser drops `#` comments and usdc
    has none, so the list lives in the prim's metadata.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings" (
            customData = {
                dictionary usdrender_lint = {
                    string[] ignore = ["SE003"]
                }
            }
        )
        {
            uniform float4 dataWindowNDC = (0, 0, 1, 1)
        }
    }
    ```

    ## Use instead
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            uniform float4 dataWindowNDC = (0, 0, 1, 1)
        }
    }
    ```

    ## Fix safety
    Safe: the fix removes the entry from the list in the layer that authors
    it and changes nothing else that is reported. An emptied list is removed,
    unless a weaker layer authors a list too: then an empty list stays, so the
    weaker entries keep being hidden as before. A malformed value has no fix.
    """

    code = "UL001"
    name = "unused-suppression"
    severity = Severity.INFO
    partial_composition = True
    fix_safety = "safe"
