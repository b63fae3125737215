"""PR001 product-name-empty."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Usd

from usdrender_lint.api import Context, Diagnostic, Fix, Rule, Severity, record, schemas
from usdrender_lint.api.resolve import prim_values

from .._aov import checked
from .._corrections import set_value


class ProductNameEmpty(Rule):
    """A RenderProduct's productName is empty.

    ## What it does
    Reports a usable RenderProduct whose `productName` (a varying `token`,
    fallback `""`) is `""` at the default time and has no time samples: left
    unauthored, authored empty, or blocked. A productName authored only as
    time samples is SE017's case, and a type-mismatched opinion SE016's.

    ## Why is this bad?
    *"Specifies the name that the output/display driver should give the
    product."* (`pxr/usd/usdRender/schema.usda`); *"e.g. using the productName
    for the filename (and path) for an output image artifact"*
    (`RenderProduct.md`). An empty name gives the display driver nothing to
    write to: renderers either fail or invent a name. A renderer profile may
    say which (`arnold`: arnold-usd's USD procedural, as kick renders the
    file, writes the image under the product prim's name), and the finding
    then says that.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderProduct "Beauty"
        {
            rel orderedVars = </Render/Vars/color>
        }

        def Scope "Vars"
        {
            def RenderVar "color"
            {
                string sourceName = "Ci"
            }
        }
    }
    ```

    ## Use instead
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderProduct "Beauty"
        {
            token productName = "beauty.exr"
            rel orderedVars = </Render/Vars/color>
        }

        def Scope "Vars"
        {
            def RenderVar "color"
            {
                string sourceName = "Ci"
            }
        }
    }
    ```

    ## Fix safety
    Safe, conditional: only when the pipeline configures a naming template
    (option `name-template`, e.g. `"{prim}.exr"`) does the fix author the
    name it gives; by default there is no fix, the output name being a
    pipeline decision. (The catalog's class: none, pipeline template.)

    ## Options
    `name-template` (string, default empty: no fix): the productName the fix
    authors; `{prim}` is replaced by the product's prim name.
    """

    code = "PR001"
    name = "product-name-empty"
    severity = Severity.ERROR
    partial_composition = True
    fix_safety = "safe-conditional"
    prim_types = (schemas.RenderProduct,)

    @record(frozen=True)
    class Options:
        name_template: str = ""

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        values = prim_values(prim)
        # may_vary: no samples are asked of an attribute that provably has none
        # (and no handle is made of it: most products have a name).
        if values.may_vary("productName") and values.attribute("productName").GetNumTimeSamples():
            return
        if checked(values, "productName") != "":
            return
        attr = values.attribute("productName")
        if attr.GetResolveInfo().ValueIsBlocked():
            how = "is blocked"
        else:
            how = "is authored empty" if attr.HasAuthoredValue() else "has no authored value"
        template = self.options.name_template
        fix = None
        if template:
            name = template.replace("{prim}", prim.GetName())
            fix = Fix(
                description=f"author productName = {name!r}",
                safe=True,
                apply=set_value(attr.GetPath(), name),
            )
        # What the renderer makes of it is its own: the profile may say
        # (arnold-usd's procedural names the file after the prim).
        behaviour = ctx.behaviour(self.code, prim)
        consequence = (
            "the display driver has no name to write to" if behaviour is None else behaviour.what
        )
        yield Diagnostic(
            message=f"RenderProduct {prim.GetPath()} has an empty productName (it {how}): "
            f"{consequence}; author one, e.g. token productName = "
            f'"{prim.GetName()}.exr"',
            at=attr if attr.IsAuthored() else prim,
            fix=fix,
        )
