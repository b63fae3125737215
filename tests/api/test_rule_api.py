"""The rule-author API as docs/guides/writing-rules.md documents it: abstract bases, aliases,
frozen keyword-only Diagnostic and Fix, and the documented imports."""

from __future__ import annotations

import dataclasses
import re

import pytest
from pxr import Usd, UsdRender

from usdrender_lint.api import Context, Diagnostic, Fix, FullStageRequired, Rule, Severity
from usdrender_lint.engine import Linter
from usdrender_lint.registry import matches_any

DOC = """Test-only rule.

    ## What it does
    ## Why is this bad?
    ## Example
    ## Use instead
    ## Fix safety
    """


def test_an_abstract_base_needs_no_code_and_its_subclasses_are_checked() -> None:
    class Base(Rule):
        abstract = True
        prim_types = (UsdRender.Product,)
        partial_composition = True

    class Concrete(Base):
        __doc__ = DOC
        code = "ZZ970"
        name = "concrete-rule"
        severity = Severity.INFO

    assert Concrete.prim_types == (UsdRender.Product,) and not Concrete.abstract
    assert Base.abstract
    with pytest.raises(TypeError, match="code None is not a prefix plus 3 digits"):

        class Forgotten(Base):  # not abstract itself: it must say what it is
            name = "forgotten"
            severity = Severity.INFO


def test_a_variant_of_a_documented_rule_keeps_its_documentation() -> None:
    class Documented(Rule):
        __doc__ = DOC
        code = "ZZ974"
        name = "documented-rule"
        severity = Severity.INFO

    class Variant(Documented):  # only its code and name change
        code = "ZZ975"
        name = "variant-rule"

    assert Variant.summary() == "Test-only rule." == Documented.summary()
    assert Variant.documentation() == DOC
    with pytest.raises(TypeError, match="no docstring"):

        class Undocumented(Rule):
            code = "ZZ976"
            name = "undocumented-rule"
            severity = Severity.INFO


def test_aliases_are_validated_and_select_the_rule() -> None:
    with pytest.raises(TypeError, match="aliases"):

        class BadAlias(Rule):
            code = "ZZ971"
            name = "bad-alias"
            severity = Severity.INFO
            aliases = ("Not Kebab",)

    class Renamed(Rule):
        __doc__ = DOC
        code = "ZZ972"
        name = "new-name"
        severity = Severity.INFO
        aliases = ("old-name",)

    assert matches_any(Renamed, ["old-name"]) and matches_any(Renamed, ["new-name"])


def test_diagnostic_and_fix_are_frozen_and_keyword_only() -> None:
    fix = Fix(description="set it", safe=True)
    diagnostic = Diagnostic(message="wrong", fix=fix)
    for value, field in ((fix, "safe"), (diagnostic, "message")):
        with pytest.raises(dataclasses.FrozenInstanceError):
            setattr(value, field, None)
    with pytest.raises(TypeError):
        Fix("set it", True)  # type: ignore[misc]
    with pytest.raises(TypeError):
        Diagnostic("wrong")  # type: ignore[misc]


def test_the_documented_context_members_exist() -> None:
    stage = Usd.Stage.CreateInMemory()
    ctx = Context(stage=stage, file="shot.usda")
    for member in ("stage", "file", "prims_of", "configurations", "untargeted_products",
                   "time_sample_cap", "cached", "require_full_stage",
                   "depends_on_asset"):  # fmt: skip
        assert hasattr(ctx, member), member
    ctx.require_full_stage()  # a fully composed stage: nothing happens
    with pytest.raises(FullStageRequired):
        Context(stage=stage, file="shot.usda", partial=True).require_full_stage()


def test_a_diagnostic_layer_names_the_layer_reported() -> None:
    from pxr import Sdf

    weak = Sdf.Layer.CreateAnonymous("weak.usda")
    weak.ImportFromString('#usda 1.0\ndef RenderSettings "S"\n{\n}\n')
    root = Sdf.Layer.CreateAnonymous("root.usda")
    root.subLayerPaths.append(weak.identifier)
    root.ImportFromString(
        f'#usda 1.0\n(\n    subLayers = [@{weak.identifier}@]\n)\nover "S"\n{{\n}}\n'
    )

    class NamesTheWeakLayer(Rule):
        __doc__ = DOC
        code = "ZZ973"
        name = "names-the-weak-layer"
        severity = Severity.INFO
        prim_types = (UsdRender.Settings,)

        def check_prim(self, prim, ctx):
            yield Diagnostic(message="here", at=prim)
            yield Diagnostic(message="there", at=prim, layer=weak)

    findings = Linter([NamesTheWeakLayer()]).lint_stage(Usd.Stage.Open(root))
    layers = {f.message: f.location.layer for f in findings}
    assert layers == {"here": root.identifier, "there": weak.identifier}


def test_a_plugin_listing_an_abstract_base_is_refused() -> None:
    from usdrender_lint.registry import RegistryError, build_registry

    class Base(Rule):
        abstract = True

    class EntryPoint:
        name, value = "acme", "acme:RULES"

        @staticmethod
        def load():
            return [Base]

    with pytest.raises(RegistryError, match="abstract base"):
        build_registry([EntryPoint()])


def test_an_options_field_without_a_default_is_refused_when_the_class_is_defined() -> None:
    # It used to define fine and then fail every unconfigured run with
    # "internal error: TypeError: Options.__init__() missing ...", naming no rule.
    from usdrender_lint.api import record

    @record(frozen=True)
    class Required:
        limit: int
        names: tuple[str, ...] = ()

    with pytest.raises(TypeError, match=r"Limited: Options field\(s\) limit have no"):

        class Limited(Rule):
            __doc__ = DOC
            code = "ZZ971"
            name = "limited-rule"
            severity = Severity.INFO
            Options = Required

    @record(frozen=True)
    class Defaulted:
        limit: int = 1
        names: tuple[str, ...] = dataclasses.field(default_factory=tuple)

    class Fine(Rule):
        __doc__ = DOC
        code = "ZZ972"
        name = "fine-rule"
        severity = Severity.INFO
        Options = Defaulted

    assert Fine().options == Defaulted()


def test_options_that_are_a_dataclass_instance_are_refused_when_the_class_is_defined() -> None:
    """``Options = Opts()`` passed (``dataclasses.is_dataclass`` holds for an
    instance), and ``rules`` and ``check`` then ended in "internal error:
    TypeError: 'Opts' object is not callable", naming neither rule nor plugin."""
    from usdrender_lint.api import record

    @record(frozen=True)
    class Opts:
        limit: int = 1

    with pytest.raises(TypeError, match=r"Made: Options is an instance of Opts, not a dataclass"):

        class Made(Rule):
            __doc__ = DOC
            code = "ZZ973"
            name = "made-rule"
            severity = Severity.INFO
            Options = Opts()  # type: ignore[assignment]


def test_a_check_prim_without_prim_types_is_refused_when_the_class_is_defined() -> None:
    # The engine hands check_prim only prims of prim_types: such a rule used to
    # load, list and run, and silently never find anything.
    with pytest.raises(TypeError, match="NoTypes: check_prim is never called: prim_types is empty"):

        class NoTypes(Rule):
            __doc__ = DOC
            code = "ZZ973"
            name = "no-types-rule"
            severity = Severity.INFO

            def check_prim(self, prim, ctx):
                yield Diagnostic(message="never", at=prim)

    class StageOnly(Rule):  # a check_stage rule needs no prim_types
        __doc__ = DOC
        code = "ZZ974"
        name = "stage-only-rule"
        severity = Severity.INFO

        def check_stage(self, ctx):
            return ()

    assert StageOnly.prim_types == ()


def test_explain_lists_the_options_a_docstring_does_not_document() -> None:
    # A plugin rule's options were shown nowhere: explain printed its docstring only.
    from usdrender_lint.api import record
    from usdrender_lint.explain import explain_text

    @record(frozen=True)
    class Limits:
        max_width: int = 4096
        names: tuple[str, ...] = ()

    class Capped(Rule):
        __doc__ = DOC
        code = "ZZ975"
        name = "capped-rule"
        severity = Severity.INFO
        Options = Limits

    text = explain_text(Capped)
    assert (
        "## Options\n- `max-width` (int, default 4096)\n"
        "- `names` (tuple[str, ...], default ())\n\n## Under each profile" in text
    )

    class Documented(Capped):
        __doc__ = DOC + "\n    ## Options\n    `max-width`: the widest.\n    "
        code = "ZZ976"
        name = "documented-rule"

    assert explain_text(Documented).count("## Options") == 1


def test_options_of_another_type_are_refused_when_the_rule_is_made() -> None:
    # Capped({"max_width": 1}) used to fail later, inside check_prim, as
    # "'dict' object has no attribute 'max_width'".
    from usdrender_lint.api import record

    @record(frozen=True)
    class Limits:
        max_width: int = 4096

    class Capped(Rule):
        __doc__ = DOC
        code = "ZZ977"
        name = "capped-made-rule"
        severity = Severity.INFO
        Options = Limits

    assert Capped(Limits(max_width=1)).options == Limits(max_width=1)
    assert Capped().options == Limits()
    with pytest.raises(
        TypeError, match=r"\(ZZ977\): options must be a Capped.Options\(...\), got dict"
    ):
        Capped({"max_width": 1})


@pytest.mark.parametrize(
    ("given", "near"),
    [
        ("renderman ", "renderman"),
        ("prman", "renderman"),
        ("Karma", "karma"),
        ("arnlod", "arnold"),
        ("rtx", "omniverse"),
    ],
)
def test_a_profile_that_does_not_exist_is_refused_when_the_class_is_defined(
    given: str, near: str
) -> None:
    # The engine runs a renderer rule only where its profile is judged present:
    # a misspelt one loaded, listed, and silently never ran.
    said = f"Misspelt: profile {given!r} is no renderer profile, so the rule would never run"
    with pytest.raises(TypeError, match=re.escape(f"{said} (did you mean {near!r}?")):

        class Misspelt(Rule):
            __doc__ = DOC
            code = "ZZ975"
            name = "misspelt-profile-rule"
            severity = Severity.INFO
            profile = given

    with pytest.raises(
        TypeError, match=re.escape("profile 'auto' is not a renderer profile: leave")
    ):

        class Auto(Rule):
            __doc__ = DOC
            code = "ZZ978"
            name = "auto-profile-rule"
            severity = Severity.INFO
            profile = "auto"

    class Renderer(Rule):  # a profile that exists, and None, are fine
        __doc__ = DOC
        code = "ZZ976"
        name = "renderer-rule"
        severity = Severity.INFO
        profile = "renderman"

    assert Renderer.profile == "renderman"


def test_a_profile_set_after_the_class_is_refused_when_it_is_registered() -> None:
    from usdrender_lint.registry import RegistryError, build_registry

    class Later(Rule):
        __doc__ = DOC
        code = "ZZ977"
        name = "later-profile-rule"
        severity = Severity.INFO

    Later.profile = "prman"

    class EntryPoint:
        name, value = "acme", "acme:RULES"

        @staticmethod
        def load():
            return [Later]

    said = "Later) of plugin 'acme' (acme:RULES): profile 'prman' is no renderer profile"
    with pytest.raises(RegistryError, match=re.escape(said)):
        build_registry([EntryPoint()])


def test_the_profile_names_a_rule_may_give_are_the_profiles() -> None:
    from usdrender_lint.model import PROFILE_NAMES
    from usdrender_lint.profiles import PROFILES

    assert tuple(PROFILES) == PROFILE_NAMES
