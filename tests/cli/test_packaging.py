"""Every package of the source tree is in pyproject's explicit package list:
a subpackage left out installs nowhere, and only a plain install would show it."""

from __future__ import annotations

import os
import re
import tomllib
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]


def test_every_package_is_listed() -> None:
    setuptools = tomllib.loads((REPO / "pyproject.toml").read_text())["tool"]["setuptools"]
    listed = set(setuptools["packages"])
    found = set()
    for root, name in (
        (REPO / "usdrender_lint", "usdrender_lint"),
        (REPO / "rules", "usdrender_lint.rules"),
    ):
        for init in root.rglob("__init__.py"):
            parts = init.parent.relative_to(root).parts
            if "usdRenderLint" in parts:
                continue  # the plugin module USD imports, mapped to its own top-level name
            found.add(".".join([name, *parts]))
    assert found <= listed, sorted(found - listed)


def test_the_checkout_is_one_package_without_path_changes() -> None:
    # The source tree's rules are reached through the usdrender_lint/rules link,
    # not by putting the checkout's root on the package's path (which made the
    # cache key cover tests/ and benchmarks/).
    import usdrender_lint
    import usdrender_lint.rules

    assert [os.path.realpath(p) for p in usdrender_lint.__path__] == [str(REPO / "usdrender_lint")]
    assert os.path.realpath(usdrender_lint.rules.__path__[0]) == str(REPO / "rules")
    link = REPO / "usdrender_lint" / "rules"
    assert link.is_symlink() and os.readlink(link) == os.path.join("..", "rules")
    assert not (REPO / "usdrender_lint" / "resolve.py").exists()


def test_the_cache_key_covers_the_rules_and_not_the_tests() -> None:
    from usdrender_lint.engine import Linter
    from usdrender_lint.running.result_cache import _code_signature
    from usdrender_lint.testing import all_rules

    files = {os.path.realpath(path) for path, _, _ in _code_signature(Linter(all_rules()))}
    assert str(REPO / "rules" / "_aov.py") in files  # a helper no rule class names
    assert not [f for f in files if f.startswith(str(REPO / "tests"))]
    assert not [f for f in files if f.startswith(str(REPO / "benchmarks"))]


_PLUGIN_RULE = '''
from usdrender_lint.api import Rule, Severity


class StudioRule(Rule):
    """A studio's rule."""

    code = "STU001"
    name = "studio-rule"
    severity = Severity.WARNING
'''


def test_the_cache_key_covers_a_plugin_rule_s_package_and_not_its_site(
    tmp_path: Path, monkeypatch
) -> None:
    """A helper module beside a plugin's rule (what its messages or checks
    import), or a data file there that it reads, is its code as much: edited,
    the key changes. A rule in a module
    at the top of site-packages brings in no other file of that folder."""
    import importlib
    import sys

    from usdrender_lint.engine import Linter
    from usdrender_lint.running.result_cache import _code_signature

    site = tmp_path / "site"
    (site / "studio_rules").mkdir(parents=True)
    (site / "studio_rules" / "__init__.py").write_text(_PLUGIN_RULE)
    (site / "studio_rules" / "words.py").write_text('MESSAGE = "one"\n')
    (site / "studio_rules" / "allowed_aovs.txt").write_text("beauty\n")  # what a check reads
    (site / "studio_rules" / ".words.py.swp").write_text("")  # an editor's, while words.py is open
    (site / "lone_rules.py").write_text(_PLUGIN_RULE.replace("STU001", "STU002"))
    (site / "unrelated.py").write_text("")
    monkeypatch.syspath_prepend(str(site))
    packaged = importlib.import_module("studio_rules").StudioRule
    lone = importlib.import_module("lone_rules").StudioRule
    try:
        files = {path for path, _, _ in _code_signature(Linter([packaged(), lone()]))}
    finally:
        sys.modules.pop("studio_rules", None)
        sys.modules.pop("lone_rules", None)
    assert str(site / "studio_rules" / "words.py") in files
    assert str(site / "studio_rules" / "allowed_aovs.txt") in files
    assert str(site / "studio_rules" / ".words.py.swp") not in files
    assert str(site / "lone_rules.py") in files
    assert str(site / "unrelated.py") not in files


def test_no_requirement_names_the_package_itself() -> None:
    # NVIDIA's Asset Validator orders its plugins by every Requires-Dist of their
    # distributions (extras' included): a self-reference such as
    # "usdrender-lint[server,watch]" is a cycle it logs as an ERROR on every start.
    project = tomllib.loads((REPO / "pyproject.toml").read_text())["project"]
    requirements = [*project["dependencies"]]
    for extra in project["optional-dependencies"].values():
        requirements += extra
    names = {
        re.split(r"[\s\[<>=!~;]", r, maxsplit=1)[0].lower().replace("_", "-") for r in requirements
    }
    assert project["name"] not in names
    # So the test extra lists the server's and the watch's requirements itself.
    extras = project["optional-dependencies"]
    assert set(extras["server"] + extras["watch"]) <= set(extras["test"])
