"""``arnold``: Arnold through arnold-usd (husk's render delegate or the USD procedural)."""

from __future__ import annotations

from ..model import Severity
from .model import Accepted, Behaviour, Profile, RuleChange

RENDER_DELEGATE_CPP = (
    "arnold-usd libs/render_delegate/render_delegate.cpp (_ParseDelegateRenderProducts)"
)
RENDER_PASS_CPP = "arnold-usd libs/render_delegate/render_pass.cpp (_CreateFilter)"
READ_OPTIONS_CPP = (
    "arnold-usd libs/translator/reader/read_options.cpp (UsdArnoldReadRenderSettings::Read)"
)
#: Where arnold-usd reads instantaneousShutter: the USD procedural (kick) sets
#: options.ignore_motion_blur when it is true and reads no disableMotionBlur;
#: the render delegate maps the setting onto ignore_motion_blur as well.
INSTANTANEOUS_SHUTTER_SRC = (
    "arnold-usd libs/translator/reader/read_options.cpp (ReadRenderSettings: "
    "GetInstantaneousShutterAttr sets options.ignore_motion_blur); "
    "libs/render_delegate/render_delegate.cpp (_SetRenderSetting: instantaneousShutter)"
)
#: How arnold-usd's USD procedural (what kick renders a .usd file with) names
#: a product's driver file: productName, else the product prim's name (.exr
#: added when it has no extension); a product that authors arnold:driver gets
#: productName as it is.
PRODUCT_FILENAME_SRC = (
    'arnold-usd libs/common/rendersettings_utils.cpp (DeduceDriverFromFilename: "If none is '
    "provided, we'll use the primitive name\"; ReadDriverFromRenderProduct when arnold:driver "
    "is authored), read by libs/translator/reader/read_options.cpp "
    "(UsdArnoldReadRenderSettings::Read)"
)
#: arnold-usd's USD procedural reads the render settings, products and vars at
#: the frame kick renders; its testsuite renders the frame-2 samples of a
#: time-sampled resolution and productName with kick -frame 2.
FRAME_READ_SRC = (
    "arnold-usd libs/common/rendersettings_utils.cpp (ReadRenderSettings: Get(..., "
    "time.frame) for resolution, productName and the vars); testsuite/test_0159 "
    '("Read render settings at the proper frame", kick -frame 2)'
)
#: arnold-usd's schema generator: every typed schema it registers is named
#: Arnold<NodeEntry> (schemaName = 'Arnold{}'.format(makeCamelCase(entryName))),
#: besides class ArnoldNodeGraph "ArnoldNodeGraph".
SCHEMA_GENERATOR = "arnold-usd schemas/createSchemaFile.py"
#: arnold-usd's render delegate strips "arnold:global:" or "arnold:" from a
#: render setting's name to find the options parameter it sets.
SETTINGS_PREFIX = (
    "arnold-usd libs/render_delegate/render_delegate.cpp (_RemoveArnoldGlobalPrefix: "
    "arnold:global: and arnold: settings)"
)

ARNOLD = Profile(
    name="arnold",
    description="Arnold through arnold-usd: the schema plus Arnold's drivers, filters and "
    "AOV naming (AR rules).",
    family="AR",
    namespaces=("arnold:",),
    api_schemas=("Arnold*",),
    evidence_sources=(
        SETTINGS_PREFIX,
        f"{SCHEMA_GENERATOR} (API schemas named Arnold<NodeEntry>API)",
    ),
    changes=(
        RuleChange(
            code="SE007",
            severity=None,
            why="arnold-usd still reads instantaneousShutter: true disables motion blur "
            "(options.ignore_motion_blur), and its USD procedural reads no disableMotionBlur, "
            "so the attribute is not ignored and replacing it with disableMotionBlur would "
            "bring motion blur back when kick renders the file",
            source=INSTANTANEOUS_SHUTTER_SRC,
        ),
        RuleChange(
            code="SE017",
            severity=Severity.INFO,
            why="arnold-usd's USD procedural reads the render settings, products and vars at "
            "the frame kick renders (husk, rendering through arnold-usd's delegate, does the "
            "same), so time samples on their uniform attributes are rendered, not ignored; only "
            "tools that read the default time, as UsdRenderComputeSpec does, get the fallback",
            source=FRAME_READ_SRC,
        ),
    ),
    behaviours=(
        Behaviour(
            code="SE017",
            what="arnold-usd reads it at the frame it renders and follows the samples",
            source=FRAME_READ_SRC,
        ),
        Behaviour(
            code="PR001",
            what="arnold-usd's USD procedural, which kick renders the file with, writes the "
            "image under the product prim's name instead (with .exr, in the working "
            "directory), and gives a product that authors arnold:driver the empty name",
            source=PRODUCT_FILENAME_SRC,
        ),
    ),
    prim_types=(
        Accepted(
            name="Arnold*",
            why="arnold-usd registers its own typed schemas, all named Arnold* "
            "(ArnoldNodeGraph for the imagers, AOV shaders, background and atmosphere the "
            "settings name, ArnoldOptions, ...); they are unknown types only where arnold-usd "
            "is not installed",
            source=f"{SCHEMA_GENERATOR}; {READ_OPTIONS_CPP}: "
            "ngPrim.GetTypeName() == _tokens->ArnoldNodeGraph",
        ),
    ),
    product_types=(
        Accepted(
            name="arnold",
            why="arnold-usd writes products of type 'arnold' with its own Arnold driver "
            "(arnold:driver, default driver_exr)",
            source=RENDER_DELEGATE_CPP,
        ),
        Accepted(
            name="deep",
            why="arnold-usd still writes products of type 'deep' with driver_deepexr, "
            "for backwards compatibility",
            source=RENDER_DELEGATE_CPP,
        ),
    ),
)
