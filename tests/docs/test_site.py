"""The documentation site: every registered rule and profile has its generated
page, every internal link (hand-written and generated pages alike) reaches a
page or file that exists, and its anchor a heading of that page. Cheap: the
pages come from docs/hooks.py without MkDocs (.ci/run builds the site with
``mkdocs build --strict``)."""

from __future__ import annotations

import importlib.util
import posixpath
import re
import sys
from pathlib import Path

import pytest

from usdrender_lint.api.docs import rule_doc
from usdrender_lint.profiles import PROFILES
from usdrender_lint.registry import build_registry

REPO = Path(__file__).resolve().parents[2]
DOCS = REPO / "docs"


def _hooks():
    spec = importlib.util.spec_from_file_location("docs_hooks", DOCS / "hooks.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up
    spec.loader.exec_module(module)
    return module


hooks = _hooks()


@pytest.fixture(scope="module")
def generated() -> dict[str, str]:
    return hooks.reference_pages()


@pytest.fixture(scope="module")
def site(generated: dict[str, str]) -> dict[str, str]:
    """Every page of the site, docs-relative path -> Markdown."""
    pages = {
        path.relative_to(DOCS).as_posix(): path.read_text(encoding="utf-8")
        for path in DOCS.rglob("*.md")
    }
    assert not set(pages) & set(generated), "a generated page is also written by hand"
    return pages | generated


def test_every_registered_rule_has_its_page(generated: dict[str, str]) -> None:
    for rule in build_registry().rules:
        page = generated[f"reference/rules/{rule.code}-{rule.name}.md"]
        assert f"\n# {rule.code} {rule.name}\n" in page
        assert "## What it does" in page and "## Under each profile" in page
        # The same documentation explain prints: every line of the rule's docstring
        # (a fence naming a supporting layer becomes a titled fence).
        missing = [
            line
            for line in rule_doc(rule).splitlines()
            if line.strip() and not line.startswith("```") and line not in page
        ]
        assert missing == [], rule.code
        index = generated["reference/rules/index.md"]
        assert f"({rule.code}-{rule.name}.md)" in index


def test_every_code_a_finding_carries_has_the_page_its_link_names(
    generated: dict[str, str],
) -> None:
    """The editors link each diagnostic's code to its page (rule_doc_url): the
    internal-error code UL000, which no rule class declares, included, with the
    text explain prints."""
    from usdrender_lint.model import DOCS_URL, INTERNAL_ERROR_RULE, rule_doc_url

    codes = [(r.code, r.name) for r in build_registry().rules]
    for code, name in [*codes, (INTERNAL_ERROR_RULE.code, INTERNAL_ERROR_RULE.name)]:
        page = rule_doc_url(code, name).removeprefix(DOCS_URL).rstrip("/") + ".md"
        assert page in generated, page
    internal = generated["reference/rules/UL000-internal-error.md"]
    assert all(line in internal for line in INTERNAL_ERROR_RULE.doc.splitlines())
    index = generated[hooks.RULES_INDEX]
    assert "[UL000](UL000-internal-error.md)" in index


def test_a_rule_page_shows_its_options_and_its_profiles(generated: dict[str, str]) -> None:
    pr001 = generated["reference/rules/PR001-product-name-empty.md"]
    assert '| `name-template` | string | `""` |' in pr001
    assert "[tool.usdrender-lint.rules.product-name-empty]" in pr001
    # omniverse switches PR001 off, with its source as a link.
    omniverse = r"- \[omniverse\]\(../profiles/omniverse.md\): off \(.*\(https://nvidia-omniverse"
    assert re.search(omniverse, pr001)


def test_every_profile_has_its_page_with_every_change(generated: dict[str, str]) -> None:
    for profile in PROFILES.values():
        page = generated[f"reference/profiles/{profile.name}.md"]
        for change in profile.changes:
            row = next(line for line in page.splitlines() if f"[{change.code}](" in line)
            assert change.why.split()[0] in row
            assert change.source.split()[0] in row
        accepted_names = (
            *profile.camera_types,
            *profile.prim_types,
            *profile.product_types,
            *profile.var_outputs,
            *profile.layer_data,
        )
        for accepted in accepted_names:
            assert f"`{accepted.name}`" in page
        for source in profile.evidence_sources:
            assert source.split()[0] in page


def test_every_profile_page_lists_all_the_evidence_auto_reads(generated: dict[str, str]) -> None:
    # What detect reads as evidence (tests/profiles/test_profile_evidence.py,
    # PRIM_EVIDENCE and LAYER_EVIDENCE), each under "When auto picks it".
    for profile in PROFILES.values():
        page = generated[f"reference/profiles/{profile.name}.md"]
        section = page.split("## When `auto` picks it", 1)[1].split("\n## ", 1)[0]
        names = [
            *profile.namespaces,
            *profile.api_schemas,
            *profile.scopes,
            *(a.name for a in profile.product_types),
            *(a.name for a in profile.camera_types),
            *(a.name for a in profile.runtime_cameras),
            *(a.name for a in profile.layer_data),
        ]
        for name in names:
            assert f"`{name}`" in section, (profile.name, name)


def test_the_configuration_reference_lists_every_key_the_parser_accepts(
    generated: dict[str, str], tmp_path: Path
) -> None:
    from usdrender_lint.config import ConfigError, load_settings

    page = generated["reference/configuration.md"]
    from usdrender_lint.settings_table import SETTINGS

    settings = hooks.settings_declaration()
    # Every key of the settings table, and its verdict on the cache key.
    assert [(s.key, s.changes_findings) for s in settings] == [
        (entry.config_key, entry.changes_findings) for entry in SETTINGS if entry.config_key
    ]
    for setting in settings:
        assert f"| `{setting.key}` |" in page
        assert setting.help, f"{setting.key} has no #: comment in its declaration"
    # Each key is one the configuration file takes; an undocumented one is not.
    config = tmp_path / ".usdrender-lint.toml"
    for key in [s.key for s in settings] + ["not-a-key"]:
        config.write_text(f"{key} = 0\n", encoding="utf-8")
        with pytest.raises(ConfigError) as error:
            load_settings(str(config))
        assert ("unknown key" in str(error.value)) == (key == "not-a-key"), error.value


def test_the_cli_reference_lists_every_command_and_option(generated: dict[str, str]) -> None:
    from usdrender_lint.cli import cli

    page = generated["reference/cli.md"]
    for name, command in cli.commands.items():
        assert f"\n## {name}\n" in page
        for param in command.params:
            if getattr(param, "hidden", False):
                continue  # --full-composition: for tests and benchmarks
            for flag in getattr(param, "opts", []):
                if flag.startswith("-"):
                    assert flag in page, (name, flag)


def test_the_cli_reference_shows_each_help_text_as_click_prints_it(
    generated: dict[str, str],
) -> None:
    # Rendered as the site renders it: Markdown took "__pypackages__" for bold.
    import html

    import click
    import markdown

    from usdrender_lint.cli import cli

    rendered = markdown.markdown(generated["reference/cli.md"], extensions=["tables"])
    shown = " ".join(html.unescape(re.sub(r"<[^>]+>", " ", rendered)).split())
    group = click.Context(cli, info_name="usdrender-lint")
    for name, command in cli.commands.items():
        ctx = click.Context(command, info_name=name, parent=group)
        for param in command.get_params(ctx):
            record = param.get_help_record(ctx)
            if record is not None and not isinstance(param, click.Argument):
                assert " ".join(record[1].split()) in shown, (name, record[0])


def test_a_profile_page_shows_its_description_as_written(generated: dict[str, str]) -> None:
    # moonray's "(moonray:sceneVariable:*) ... (parameters:moonray:*)" lost both stars.
    import html

    import markdown

    for profile in PROFILES.values():
        for page in (hooks.profile_page(profile.name), hooks.PROFILES_INDEX):
            rendered = markdown.markdown(generated[page], extensions=["tables"])
            shown = " ".join(html.unescape(re.sub(r"<[^>]+>", " ", rendered)).split())
            assert " ".join(profile.description.split()) in shown, (page, profile.name)


def _slug(heading: str) -> str:
    """Python-Markdown's toc slug: lower case, no punctuation, spaces to '-'."""
    text = re.sub(r"<[^>]+>|`", "", heading)
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", text)
    text = re.sub(r"[^\w\s-]", "", text).strip().lower()
    return re.sub(r"[-\s]+", "-", text)


def _anchors(markdown: str) -> set[str]:
    text = re.sub(r"```.*?```", "", markdown, flags=re.DOTALL)
    found = {_slug(m.group(1)) for m in re.finditer(r"^#{1,6}\s+(.+?)\s*$", text, re.MULTILINE)}
    return found | set(re.findall(r"\{\s*#([\w-]+)\s*\}", text))


def test_no_internal_link_is_broken(site: dict[str, str]) -> None:
    files = {p.relative_to(DOCS).as_posix() for p in DOCS.rglob("*") if p.is_file()}
    files.add(hooks.CONFIG_SCHEMA)  # generated at build time, as the reference pages are
    broken = []
    for page, markdown in site.items():
        for target in hooks._iter_links(markdown):
            if re.match(r"[a-z]+:", target):
                continue  # http:, https:, mailto:
            path, _, anchor = target.partition("#")
            resolved = (
                posixpath.normpath(posixpath.join(posixpath.dirname(page), path)) if path else page
            )
            if resolved not in site and resolved not in files:
                broken.append(f"{page}: {target} (no such page)")
            elif anchor and resolved in site and anchor not in _anchors(site[resolved]):
                broken.append(f"{page}: {target} (no such heading)")
    assert broken == []


def test_every_page_is_in_the_navigation(site: dict[str, str]) -> None:
    yaml = pytest.importorskip("yaml")
    config = (REPO / "mkdocs.yml").read_text(encoding="utf-8")
    # mkdocs.yml's nav only: its other keys use tags PyYAML's safe loader refuses.
    nav = yaml.safe_load("nav:" + config.split("\nnav:", 1)[1])["nav"]
    nav = hooks._expand(
        nav,
        {
            hooks.RULES_INDEX: hooks._rules_nav(list(build_registry().rules)),
            hooks.PROFILES_INDEX: hooks._profiles_nav(),
        },
    )
    listed = set(re.findall(r"'([^']+\.md)'", repr(nav)))
    assert set(site) - listed == set()
    assert listed - set(site) == set()


def test_every_release_the_docs_name_is_this_version(site: dict[str, str]) -> None:
    """The version lives in usdrender_lint.__version__; the tags the docs and
    examples pin (pre-commit's rev, pip's @vX.Y.Z) follow it."""
    from usdrender_lint import __version__

    texts = dict(site)
    for path in (
        "README.md",
        "examples/.pre-commit-config.yaml",
        "examples/github-workflow.yml",
        "examples/github-workflow-sharded.yml",
    ):
        texts[path] = (REPO / path).read_text(encoding="utf-8")
    texts.pop("changelog.md")  # lists every release
    named = {
        (path, tag)
        for path, text in texts.items()
        for tag in re.findall(r"(?:rev: |@|--ref )v(\d+\.\d+\.\d+)", text)
    }
    assert {path for path, _ in named} >= {"guides/pre-commit.md", "getting-started.md"}
    assert {(path, tag) for path, tag in named if tag != __version__} == set()


def test_the_changelog_has_this_version() -> None:
    from usdrender_lint import __version__

    changelog = (REPO / "CHANGELOG.md").read_text(encoding="utf-8")
    assert f"\n## {__version__}\n" in changelog
    assert "\n## Unreleased\n" in changelog


def test_a_released_version_s_notes_are_those_of_its_tag() -> None:
    """Notes written after a release belong under Unreleased: entries added
    after 0.3.0 went into its section once, so the notes of 0.3.0 claimed what
    its tag does not hold. Each version's lists (from its first ``###``) read
    as at its tag, where the clone has Git and the tags; its opening paragraph
    may gain a remark (0.2.0's on the moved ``v0.1.0`` tag)."""
    import shutil
    import subprocess

    if shutil.which("git") is None or not (REPO / ".git").exists():
        pytest.skip("needs a Git clone of the project")
    tags = subprocess.run(
        ["git", "tag", "--list", "v*"], cwd=REPO, capture_output=True, text=True
    ).stdout.split()
    if not tags:
        pytest.skip("the clone has no release tags")

    def section(text: str, version: str) -> str:
        start = text.index("\n### ", text.index(f"\n## {version}\n"))
        end = text.find("\n## ", start)
        return text[start : end if end != -1 else len(text)]

    now = (REPO / "CHANGELOG.md").read_text(encoding="utf-8")
    for tag in tags:
        then = subprocess.run(
            ["git", "show", f"{tag}:CHANGELOG.md"], cwd=REPO, capture_output=True, text=True
        )
        if then.returncode == 0 and f"\n## {tag[1:]}\n" in then.stdout:
            assert section(now, tag[1:]) == section(then.stdout, tag[1:]), tag


def test_the_contributing_page_names_every_test_that_reads_shared() -> None:
    page = (DOCS / "contributing.md").read_text(encoding="utf-8")
    section = page.split("## Tests that need `../shared`", 1)[1].split("\n## ", 1)[0]
    named = set(re.findall(r"`(?:tests/\w+/)?(test_\w+\.py)`", section))
    readers = {
        path.name
        for path in (REPO / "tests").rglob("test_*.py")
        if re.search(r"\bshared_dir\b|\bSHARED\b", path.read_text(encoding="utf-8"))
    } - {"test_shared_skips.py"}
    assert readers - named == set()


def test_no_page_installs_from_a_package_index(site: dict[str, str]) -> None:
    """usdrender-lint is on no index yet: every install is from a clone (.) or a
    Git tag (``usdrender-lint[extra] @ git+URL@vX.Y.Z``), never ``pip install
    usdrender-lint`` or ``usdrender-lint==X``."""
    texts = {**site, "README.md": (REPO / "README.md").read_text(encoding="utf-8")}
    wrong = [
        f"{page}: {line.strip()}"
        for page, text in texts.items()
        for line in text.splitlines()
        if re.search(
            r"pip install\b.*['\"\s]usdrender-lint\b(?![-\w]*(?:\[[\w,]+\])?\s*@\s*git\+)", line
        )
        or "usdrender-lint==" in line
    ]
    assert wrong == []
