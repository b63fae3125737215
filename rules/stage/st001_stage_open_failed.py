"""ST001 stage-open-failed."""

from __future__ import annotations

from usdrender_lint.api import Rule, Severity


class StageOpenFailed(Rule):
    """The file cannot be opened as a USD stage.

    ## What it does
    Reports each error USD raises while opening the file (`Usd.Stage.Open`),
    with the file, line and column USD gives. The engine emits this finding
    itself when the open fails and then runs no other rule on the file; it is
    reported even when not selected, so a broken file is never a silent pass.

    ## Why is this bad?
    Nothing else can be checked on a stage that does not compose, and the
    renderer cannot open it either. The official
    `pxr/usd/usdRender/doxygen/renderSettings.usda` example begins with
    `#usda1.0`, which usd-core 26.11 rejects: *"Invalid layer header '#usda1.0'
    does not start with '#usda '"*.

    ## Example
    ```usda
    #usda1.0

    def Scope "Render"
    {
    }
    ```

    ## Use instead
    ```usda
    #usda 1.0

    def Scope "Render"
    {
    }
    ```

    ## Fix safety
    No automatic fix: repair the file by hand at the line and column reported.
    """

    code = "ST001"
    name = "stage-open-failed"
    severity = Severity.ERROR
    partial_composition = True
