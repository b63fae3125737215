"""ACME's render conventions as usdrender-lint rules (an example plugin)."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Sdf, Usd, UsdRender

from usdrender_lint.api import Context, Diagnostic, Fix, Rule, Severity, record


class AcmeProductRule(Rule):
    """Shared by ACME's product rules (not a rule itself)."""

    abstract = True
    prim_types = (UsdRender.Product,)
    # Reads only the product's own attributes: the engine may compose only the
    # render prims, their targets and ancestors.
    partial_composition = True


def product_name(ctx: Context, prim: Usd.Prim) -> str:
    """The composed productName; several ACME rules read it, once per lint."""
    return str(prim.GetAttribute("productName").Get() or "")


class ProductNameFrameToken(AcmeProductRule):
    """Every productName carries a frame token.

    ## What it does
    Reports a RenderProduct whose productName has no `####` frame token.

    ## Why is this bad?
    The farm writes every frame of the shot to the same file, and only the
    last one survives.

    ## Example
    ```usda
    #usda 1.0
    def RenderProduct "beauty"
    {
        token productName = "beauty.exr"
    }
    ```

    ## Use instead
    ```usda
    #usda 1.0
    def RenderProduct "beauty"
    {
        token productName = "beauty.####.exr"
    }
    ```

    ## Fix safety
    Safe: the fix inserts `.####` before the extension in the layer that
    authors productName; nothing else reads the name.

    ## Options
    - `token` (default `"####"`): the frame token the farm expands, e.g.
      `"$F4"` for a farm that reads Houdini's variables.
    """

    code = "ACME001"
    name = "product-name-frame-token"
    severity = Severity.WARNING
    fix_safety = "safe"

    @record(frozen=True)
    class Options:
        token: str = "####"

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        token = self.options.token
        name = ctx.cached(product_name, prim)
        if not name or token in name:
            return
        stem, dot, extension = name.rpartition(".")
        fixed = f"{stem}.{token}.{extension}" if dot else f"{name}.{token}"
        path = prim.GetAttribute("productName").GetPath()
        yield Diagnostic(
            message=f"productName {name!r} has no frame token {token}",
            at=prim.GetAttribute("productName"),
            fix=Fix(description=f"rename to {fixed!r}", safe=True, apply=_set_token(path, fixed)),
        )


class ProductNameNotAbsolute(AcmeProductRule):
    """A productName is relative to the farm's output root.

    ## What it does
    Reports a RenderProduct whose productName is an absolute path.

    ## Why is this bad?
    ACME's farm prefixes every output with the job's folder; an absolute name
    writes outside it, over another shot's frames.

    ## Example
    ```usda
    #usda 1.0
    def RenderProduct "beauty"
    {
        token productName = "/mnt/render/beauty.####.exr"
    }
    ```

    ## Use instead
    ```usda
    #usda 1.0
    def RenderProduct "beauty"
    {
        token productName = "beauty.####.exr"
    }
    ```

    ## Fix safety
    No automatic fix: only the author knows the intended relative name.
    """

    code = "ACME002"
    name = "product-name-not-absolute"
    severity = Severity.ERROR

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        name = ctx.cached(product_name, prim)
        if name.startswith("/"):
            yield Diagnostic(
                message=f"productName {name!r} is absolute; name it relative to the job folder",
                at=prim.GetAttribute("productName"),
            )


def _set_token(path: Sdf.Path, value: str):
    def apply(stage: Usd.Stage) -> None:
        stage.GetAttributeAtPath(path).Set(value)

    return apply


RULES = [ProductNameFrameToken, ProductNameNotAbsolute]
