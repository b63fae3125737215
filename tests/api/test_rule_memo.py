"""Values the rules share through ``Context.memo``: read once per lint, never
carried over to the next lint of a changed stage."""

from __future__ import annotations

import pytest
from pxr import Sdf, Usd
from rule_support import patch_usd

from usdrender_lint.api import Context, resolve
from usdrender_lint.api.cache import lint_cache
from usdrender_lint.api.resolve import prim_values
from usdrender_lint.engine import Linter
from usdrender_lint.rules.stage._settings_path import settings_path_opinion
from usdrender_lint.testing import all_rules

SHOT = """#usda 1.0
def Camera "cam"
{
}
def Scope "Render"
{
    def RenderSettings "Settings"
    {
        rel camera = </cam>
        rel products = </Render/beauty>
    }
    def RenderProduct "beauty"
    {
        rel orderedVars = [</Render/color>, </Render/alpha>]
    }
    def RenderVar "color"
    {
        uniform string sourceName = "Ci"
    }
    def RenderVar "alpha"
    {
        uniform string sourceName = "a"
    }
    def RenderPass "pass"
    {
        uniform token passType = "prman"
    }
}
"""


def _codes(linter: Linter, stage: Usd.Stage) -> set[tuple[str, str]]:
    return {(f.code, f.location.path) for f in linter.lint_stage(stage)}


@pytest.fixture
def stage() -> Usd.Stage:
    layer = Sdf.Layer.CreateAnonymous(".usda")
    layer.ImportFromString(SHOT)
    return Usd.Stage.Open(layer)


def _record_attribute_calls(monkeypatch, method: str) -> list[str]:
    """Patch ``Usd.Attribute.<method>`` to record the attribute path of each call."""
    calls: list[str] = []
    original = getattr(Usd.Attribute, method)

    def recording(attr, *args):
        calls.append(str(attr.GetPath()))
        return original(attr, *args)

    patch_usd(monkeypatch, Usd.Attribute, method, recording)
    return calls


def test_a_render_var_value_is_read_once_per_lint(stage, monkeypatch) -> None:
    reads = _record_attribute_calls(monkeypatch, "Get")
    Linter(all_rules(), raise_errors=True).lint_stage(stage)
    # PR006, VA001, VA002, VA003, VA008 and the profiles read them.
    assert reads.count("/Render/color.sourceName") == 1
    assert reads.count("/Render/color.sourceType") == 0  # unauthored: its fallback


def test_a_changed_stage_is_read_again(stage) -> None:
    linter = Linter(all_rules(), raise_errors=True)
    assert ("PR006", "/Render/beauty.orderedVars") not in _codes(linter, stage)
    stage.GetPrimAtPath("/Render/alpha").GetAttribute("sourceName").Set("Ci")
    assert ("PR006", "/Render/beauty.orderedVars") in _codes(linter, stage)
    stage.GetPrimAtPath("/Render/beauty").GetRelationship("orderedVars").SetTargets(
        ["/Render/color"]
    )
    assert ("PR006", "/Render/beauty.orderedVars") not in _codes(linter, stage)


def test_a_camera_attribute_is_read_once_per_lint(stage, monkeypatch) -> None:
    reads = _record_attribute_calls(monkeypatch, "HasAuthoredValue")
    Linter(all_rules(), raise_errors=True).lint_stage(stage)
    assert reads.count("/cam.projection") == 1  # CA005 twice, CA009
    assert reads.count("/cam.horizontalAperture") == 1  # CA005, CA006


def test_a_changed_camera_is_read_again(stage) -> None:
    linter = Linter(all_rules(), raise_errors=True)
    assert ("CA005", "/cam.verticalAperture") not in _codes(linter, stage)
    stage.GetPrimAtPath("/cam").GetAttribute("verticalAperture").Set(0.0)
    assert ("CA005", "/cam.verticalAperture") in _codes(linter, stage)


def test_render_prim_attributes_are_listed_once_for_se016_and_se017(stage, monkeypatch) -> None:
    listed: list[str] = []
    authored_names = Usd.Prim.GetAuthoredPropertyNames

    def counting(prim):
        listed.append(str(prim.GetPath()))
        return authored_names(prim)

    patch_usd(monkeypatch, Usd.Prim, "GetAuthoredPropertyNames", counting)
    rules = [r for r in all_rules() if r.code in ("SE016", "SE017")]
    Linter(rules, raise_errors=True).lint_stage(stage)
    assert sorted(listed) == sorted(set(listed))
    assert "/Render/color" in listed


def test_a_changed_render_prim_attribute_is_listed_again(stage) -> None:
    linter = Linter(all_rules(), raise_errors=True)
    assert ("SE016", "/Render/beauty.pixelAspectRatio") not in _codes(linter, stage)
    owner = stage.GetRootLayer().GetPrimAtPath("/Render/beauty")
    Sdf.AttributeSpec(owner, "pixelAspectRatio", Sdf.ValueTypeNames.Double).default = 1.0
    assert ("SE016", "/Render/beauty.pixelAspectRatio") in _codes(linter, stage)


def test_a_collection_authored_after_a_lint_is_checked(stage) -> None:
    linter = Linter(all_rules(), raise_errors=True)
    assert ("PA005", "/Render/pass.collection:prune:expansionRule") not in _codes(linter, stage)
    collection = Usd.CollectionAPI(stage.GetPrimAtPath("/Render/pass"), "prune")
    collection.CreateExpansionRuleAttr().Set("expandEverything")
    assert ("PA005", "/Render/pass.collection:prune:expansionRule") in _codes(linter, stage)


def _record_validated(monkeypatch) -> list[str]:
    validated: list[str] = []
    validate = Usd.CollectionAPI.Validate

    def counting(collection):
        validated.append(collection.GetName())
        return validate(collection)

    patch_usd(monkeypatch, Usd.CollectionAPI, "Validate", counting)
    return validated


def test_collections_left_to_their_fallbacks_are_not_evaluated(stage, monkeypatch) -> None:
    validated = _record_validated(monkeypatch)
    Usd.CollectionAPI(stage.GetPrimAtPath("/Render/pass"), "matte").CreateIncludesRel()
    Linter(all_rules(), raise_errors=True).lint_stage(stage)
    assert validated == ["matte"]


def test_only_properties_inside_a_collection_namespace_make_it_authored(stage, monkeypatch) -> None:
    # "collection:matte" itself and "collection:matteX:..." are not in matte's
    # namespace; an includes rel authored in a referenced layer is.
    referenced = Sdf.Layer.CreateAnonymous(".usda")
    referenced.ImportFromString(
        '#usda 1.0\ndef RenderPass "p"\n{\n    rel collection:prune:includes = </cam>\n}\n'
    )
    render_pass = stage.GetPrimAtPath("/Render/pass")
    render_pass.GetReferences().AddReference(referenced.identifier, "/p")
    render_pass.CreateAttribute("collection:matte", Sdf.ValueTypeNames.Opaque)
    render_pass.CreateAttribute("collection:matteX:foo", Sdf.ValueTypeNames.Token)
    validated = _record_validated(monkeypatch)
    Linter(all_rules(), raise_errors=True).lint_stage(stage)
    assert validated == ["prune"]


def test_the_settings_path_opinion_is_read_once_per_lint(stage, monkeypatch) -> None:
    stage.SetMetadata("renderSettingsPrimPath", "/Render/Settings")
    reads: list[str] = []
    pseudo_root = Sdf.Layer.pseudoRoot

    def counting(layer):
        reads.append(layer.identifier)
        return pseudo_root.fget(layer)

    monkeypatch.setattr(Sdf.Layer, "pseudoRoot", property(counting))
    settings_path_opinion(Context(stage=stage, file="shot.usda"))
    one_reading = len(reads)
    reads.clear()
    rules = [r for r in all_rules() if r.code in ("ST003", "ST004", "ST005", "ST006", "ST007")]
    Linter(rules, raise_errors=True).lint_stage(stage)
    assert one_reading and len(reads) == one_reading


def test_a_changed_settings_path_is_read_again(stage) -> None:
    linter = Linter(all_rules(), raise_errors=True)
    stage.SetMetadata("renderSettingsPrimPath", "/Render/Settings")
    assert not {code for code, _ in _codes(linter, stage)} & {"ST003", "ST005"}
    stage.SetMetadata("renderSettingsPrimPath", "/Render/Missing")
    assert "ST005" in {code for code, _ in _codes(linter, stage)}
    stage.SetMetadata("renderSettingsPrimPath", "")
    assert "ST003" in {code for code, _ in _codes(linter, stage)}


def test_ordered_vars_targets_are_resolved_once_per_lint(stage, monkeypatch) -> None:
    resolved: list[str] = []
    forwarded_targets = Usd.Relationship.GetForwardedTargets

    def recording(rel):
        resolved.append(str(rel.GetPath()))
        return forwarded_targets(rel)

    patch_usd(monkeypatch, Usd.Relationship, "GetForwardedTargets", recording)
    Linter(all_rules(), raise_errors=True).lint_stage(stage)
    assert resolved.count("/Render/beauty.orderedVars") == 1  # PR005, PR006, VA008, profiles


def test_a_changed_ordered_vars_target_is_resolved_again(stage) -> None:
    linter = Linter(all_rules(), raise_errors=True)
    assert ("PR005", "/Render/beauty.orderedVars") not in _codes(linter, stage)
    stage.GetPrimAtPath("/Render/alpha").SetActive(False)
    assert ("PR005", "/Render/beauty.orderedVars") in _codes(linter, stage)


def _file_stage(folder, text: str, name: str = "shot.usda") -> Usd.Stage:
    path = folder / name
    path.write_text(text)
    return Usd.Stage.Open(str(path))


def test_an_unauthored_attribute_is_answered_from_the_prim_property_names(
    tmp_path, monkeypatch
) -> None:
    # A file layer without value clips: a name no layer lists holds no value,
    # so no attribute handle or HasAuthoredValue is asked for it.
    stage = _file_stage(tmp_path, SHOT)
    asked = _record_attribute_calls(monkeypatch, "HasAuthoredValue")
    reads = _record_attribute_calls(monkeypatch, "Get")
    sampled = _record_attribute_calls(monkeypatch, "GetTimeSamples")
    counted = _record_attribute_calls(monkeypatch, "GetNumTimeSamples")
    handles: list[str] = []
    get_attribute = Usd.Prim.GetAttribute

    def recording(prim, name):
        handles.append(f"{prim.GetPath()}.{name}")
        return get_attribute(prim, name)

    patch_usd(monkeypatch, Usd.Prim, "GetAttribute", recording)
    Linter(all_rules(), raise_errors=True).lint_stage(stage)
    # CA005, CA008, CA009 read these camera attributes; SE001, SE002, SE006... the products'.
    for unauthored in ("/cam.projection", "/cam.shutter:open", "/Render/beauty.resolution"):
        assert unauthored not in asked
        assert unauthored not in handles
    # Authored: its strongest spec's default is the value (no block, a string),
    # read once from the prim's only spec, without a handle, HasAuthoredValue or Get.
    assert "/Render/color.sourceName" not in handles
    assert "/Render/color.sourceName" not in asked
    assert "/Render/color.sourceName" not in reads
    # PR001 and PR002 ask no samples of a productName that provably has none.
    assert "/Render/beauty.productName" not in sampled + counted


CLIPPED_SHOT = """#usda 1.0
def Camera "cam" (
    clips = {
        dictionary default = {
            asset[] assetPaths = [@./clip.usda@]
            asset manifestAssetPath = @./manifest.usda@
            string primPath = "/cam"
            double2[] active = [(1, 0)]
            double2[] times = [(1, 1), (2, 2)]
        }
    }
)
{
}
def Scope "Render"
{
    def RenderSettings "Settings"
    {
        rel camera = </cam>
        rel products = </Render/beauty>
    }
    def RenderProduct "beauty"
    {
        token productName = "beauty.exr"
    }
}
"""


def test_a_value_only_value_clips_give_is_authored(tmp_path) -> None:
    # No layer of the stage has a spec of focalLength: only the clip gives it
    # a value, so the prim's property names cannot decide.
    clip = '#usda 1.0\nover "cam"\n{\n    float focalLength.timeSamples = {1: -5, 2: -5}\n}\n'
    (tmp_path / "clip.usda").write_text(clip)
    (tmp_path / "manifest.usda").write_text('#usda 1.0\nover "cam"\n{\n    float focalLength\n}\n')
    stage = _file_stage(tmp_path, CLIPPED_SHOT)
    assert "focalLength" not in stage.GetPrimAtPath("/cam").GetAuthoredPropertyNames()
    assert ("CA005", "/cam.focalLength") in _codes(Linter(all_rules(), raise_errors=True), stage)


def test_each_opinion_of_an_attribute_is_read_once_per_lint(stage, monkeypatch) -> None:
    read: list[str] = []
    has_default = Sdf.PropertySpec.HasDefaultValue
    default = Sdf.PropertySpec.default

    def recording(spec):
        read.append(str(spec.path))
        return has_default(spec)

    def reading(spec):
        read.append(str(spec.path))
        return default.fget(spec)

    monkeypatch.setattr(Sdf.PropertySpec, "HasDefaultValue", recording)
    monkeypatch.setattr(Sdf.PropertySpec, "default", property(reading, default.fset))
    Linter(all_rules(), raise_errors=True).lint_stage(stage)
    # SE016 (its type), PR006, VA001... (well-typed?), VA007 (mismatched?) read it:
    # whether it holds a default (its strongest spec's read in place of asking) once.
    assert read.count("/Render/color.sourceName") == 1


def test_a_prim_type_is_asked_once_per_lint(stage, monkeypatch) -> None:
    asked: list[str] = []
    is_a = Usd.Prim.IsA

    def recording(prim, schema):
        asked.append(str(prim.GetPath()))
        return is_a(prim, schema)

    patch_usd(monkeypatch, Usd.Prim, "IsA", recording)
    # Render schemas' answers are kept for the process by type name: none yet.
    monkeypatch.setattr(resolve, "_SCHEMA_IS_A", {})
    Linter(all_rules(), raise_errors=True).lint_stage(stage)
    assert asked.count("/cam") == 1  # CA003, CA004 and every camera rule's configuration
    assert asked.count("/Render/color") == 1  # PR005, PR006's vars


def test_a_relationship_no_layer_lists_has_no_targets_without_a_handle(monkeypatch) -> None:
    layer = Sdf.Layer.CreateAnonymous(".usda")
    layer.ImportFromString(SHOT)
    stage = Usd.Stage.Open(layer)
    product = stage.GetPrimAtPath("/Render/beauty")
    handles: list[str] = []
    get_relationship = Usd.Prim.GetRelationship

    def recording(prim, name):
        handles.append(name)
        return get_relationship(prim, name)

    patch_usd(monkeypatch, Usd.Prim, "GetRelationship", recording)
    with lint_cache():  # relationships have no value clips: whatever the stage holds
        values = prim_values(product)
        assert values.targets("camera") == () and values.forwarded("camera") == ()
        assert [t.path for t in values.targets("orderedVars")] == [
            Sdf.Path("/Render/color"),
            Sdf.Path("/Render/alpha"),
        ]
    assert handles == ["orderedVars"]


LENS_SHOT = SHOT.replace(
    'def Camera "cam"\n{\n}',
    'def Camera "cam"\n{\n    float focalLength = 35\n    float horizontalAperture = 36\n}',
)


def test_an_attribute_without_samples_is_not_asked_for_them(tmp_path, monkeypatch) -> None:
    # Its opinions (read once for SE016) hold no samples and the stage has
    # no value clips: SE017 asks no value source, the camera rules no count.
    stage = _file_stage(tmp_path, LENS_SHOT)
    sources = _record_attribute_calls(monkeypatch, "GetResolveInfo")
    counts = _record_attribute_calls(monkeypatch, "GetNumTimeSamples")
    Linter(all_rules(), raise_errors=True).lint_stage(stage)
    assert "/Render/color.sourceName" not in sources
    assert "/cam.focalLength" not in counts and "/cam.horizontalAperture" not in counts


def test_a_time_sampled_attribute_is_still_asked(tmp_path, monkeypatch) -> None:
    sampled = LENS_SHOT.replace(
        "float focalLength = 35", "float focalLength.timeSamples = {1: 35, 2: 50}"
    )
    stage = _file_stage(tmp_path, sampled)
    counts = _record_attribute_calls(monkeypatch, "GetNumTimeSamples")
    Linter(all_rules(), raise_errors=True).lint_stage(stage)
    assert "/cam.focalLength" in counts


def test_a_schema_fallback_is_read_once_per_definition(stage, monkeypatch) -> None:
    # Two settings leave resolution to the fallback (SE001 reads it for each).
    stage.DefinePrim("/Render/Settings2", "RenderSettings")
    read: list[str] = []
    fallback = Usd.PrimDefinition.GetAttributeFallbackValue

    def recording(definition, name):
        read.append(name)
        return fallback(definition, name)

    patch_usd(monkeypatch, Usd.PrimDefinition, "GetAttributeFallbackValue", recording)
    Linter(all_rules(), raise_errors=True).lint_stage(stage)
    assert read.count("resolution") == 1


def test_a_target_path_resolves_once_per_lint_and_stage(stage) -> None:
    # One lint may resolve paths of two stages: each stage's own prims answer.
    other = Usd.Stage.CreateInMemory()
    other.DefinePrim("/cam", "Scope").SetActive(False)
    path = Sdf.Path("/cam")
    with lint_cache():
        target = resolve.resolve_target(stage, path)
        assert target.ok
        assert resolve.resolve_target(stage, path) is target
        assert prim_values(stage.GetPrimAtPath("/Render/Settings")).targets("camera")[0] is target
        assert resolve.resolve_target(other, path).problem == "is inactive"
