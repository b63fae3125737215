"""The README stays short and true: its two set-up commands are the ones CI
runs, the output it shows is what the first one prints, its links reach files
of the repository, and no user page carries the project's own history (issue
numbers, commit hashes). The plugin guide's example rule works as written."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from click.testing import CliRunner

from usdrender_lint.api.docs import code_blocks, sections
from usdrender_lint.cli import cli
from usdrender_lint.engine import Linter

REPO = Path(__file__).parents[2]
README = REPO / "README.md"
#: What a newcomer reads in five minutes.
MAX_WORDS = 1500


def _readme() -> str:
    return README.read_text(encoding="utf-8")


def test_the_readme_is_short() -> None:
    assert len(_readme().split()) <= MAX_WORDS


def test_ci_runs_the_readme_test_command_exactly() -> None:
    command = re.search(r"```sh\n(python3 -m venv .* -m pytest[^\n]*)\n```", _readme()).group(1)
    ci = (REPO / ".ci" / "run").read_text(encoding="utf-8")
    assert command in ci.splitlines()


def test_the_first_command_prints_what_the_readme_shows(monkeypatch: pytest.MonkeyPatch) -> None:
    text = _readme()
    command = re.search(r"```sh\n(python3 -m venv .*usdrender-lint check ([^\n]*))\n```", text)
    shown = text[text.index("```text\n", command.end()) + 8 :].split("```", 1)[0].splitlines()
    monkeypatch.chdir(REPO)
    run = CliRunner().invoke(cli, ["check", *command.group(2).split()])
    assert run.exit_code == 1  # as the README says: the broken shot fails
    printed = run.stdout.splitlines()
    assert shown[-1] == printed[-1]  # the summary, in full
    for line in shown[:-1]:
        if line == "...":
            continue
        # Abridged lines end in "...": what is shown is how a printed line starts.
        parts = [p for p in line.split(" ...") if p]
        assert any(all(p.strip(" ]") in out for p in parts) for out in printed), line


def test_the_install_sections_name_every_dependency() -> None:
    import tomllib

    project = tomllib.loads((REPO / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    names = [re.split(r"[\s\[<>=!~;]", r, maxsplit=1)[0] for r in project["dependencies"]]
    for page in (README, REPO / "docs" / "getting-started.md"):
        install = page.read_text(encoding="utf-8").split("## Install", 1)[1].split("\n\n")[1]
        assert [n for n in names if f"`{n}`" not in install] == [], page.name


def test_the_readme_links_reach_files_of_the_repository() -> None:
    targets = re.findall(r"\]\(([^)#\s]+)\)", _readme())
    local = [t for t in targets if not re.match(r"[a-z]+:", t)]
    assert len(local) >= 10
    assert [t for t in local if not (REPO / t).exists()] == []


#: The project's history: issue numbers (an HTML entity such as &#124; is none),
#: commit hashes, sessions.
HISTORY = (r"\bissues? \d+\b", r"(?<!&)#\d{2,}\b", r"`[0-9a-f]{7,40}`", r"\bsession \d+\b")


def test_no_user_page_carries_issue_numbers_or_commit_hashes() -> None:
    pages = [README, REPO / "CHANGELOG.md", *sorted((REPO / "docs").rglob("*.md"))]
    found = []
    for page in pages:
        text = page.read_text(encoding="utf-8")
        for pattern in HISTORY:
            found += [f"{page.relative_to(REPO)}: {m}" for m in re.findall(pattern, text)]
    assert found == []


def _guide_and_its_rule() -> tuple[str, type]:
    """The rule-writing guide's text and the rule class its example defines."""
    guide = (REPO / "docs" / "guides" / "writing-rules.md").read_text(encoding="utf-8")
    source = re.search(r"```python\n(# acme_rules\.py\n.*?)\n```\n", guide, re.DOTALL).group(1)
    namespace: dict = {}
    exec(compile(source, "acme_rules.py", "exec"), namespace)  # noqa: S102 - our own guide
    (rule_class,) = namespace["RULES"]
    return guide, rule_class


def test_third_party_rule_example_works(tmp_path: Path) -> None:
    guide, rule_class = _guide_and_its_rule()
    doc = sections(rule_class)
    for section, fires in (("Example", True), ("Use instead", False)):
        layer = tmp_path / f"{fires}.usda"
        layer.write_text(code_blocks(doc[section])[0])
        result = Linter([rule_class()], raise_errors=True).lint_path(str(layer))
        assert any(f.code == "ACME001" for f in result.findings) is fires


def test_the_guide_s_fixture_example_passes_for_its_example_rule(tmp_path: Path) -> None:
    # Its expect lines once named messages ("has no lights") and a whole-stage
    # finding the example rule never reports: copied, they failed.
    from usdrender_lint.testing import check_fixture

    guide, rule_class = _guide_and_its_rule()
    (fixture,) = [block for block in code_blocks(guide) if "# expect:" in block]
    path = tmp_path / "fail_guide.usda"
    path.write_text(fixture, encoding="utf-8")
    check_fixture(path, "ACME001", rules=[rule_class()])
