"""Shell completion works as Getting started documents it, for bash, zsh and
fish (click's completion, reached through the command's own entry point)."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
PAGE = REPO / "docs" / "getting-started.md"


def _run(**env: str) -> str:
    run = subprocess.run(
        [sys.executable, "-m", "usdrender_lint"],
        env={**os.environ, **env},
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert run.returncode == 0, run.stderr
    return run.stdout


def test_each_documented_shell_gets_its_script() -> None:
    documented = re.findall(
        r"_USDRENDER_LINT_COMPLETE=(\w+)_source usdrender-lint", PAGE.read_text()
    )
    assert set(documented) == {"bash", "zsh", "fish"}
    for shell in ("bash", "zsh", "fish"):
        script = _run(_USDRENDER_LINT_COMPLETE=f"{shell}_source")
        assert "_usdrender_lint_completion" in script, shell
        assert "_USDRENDER_LINT_COMPLETE" in script, shell


def test_completion_offers_commands_and_option_values() -> None:
    commands = _run(
        _USDRENDER_LINT_COMPLETE="bash_complete", COMP_WORDS="usdrender-lint ch", COMP_CWORD="1"
    )
    assert "plain,check" in commands.splitlines()
    profiles = _run(
        _USDRENDER_LINT_COMPLETE="bash_complete",
        COMP_WORDS="usdrender-lint check --profile ",
        COMP_CWORD="3",
    )
    assert {"plain,auto", "plain,karma"} <= set(profiles.splitlines())


def test_completion_run_by_hand_is_one_line_and_exit_2() -> None:
    env = {k: v for k, v in os.environ.items() if k != "COMP_WORDS"}
    done = subprocess.run(
        [sys.executable, "-m", "usdrender_lint"],
        env={**env, "_USDRENDER_LINT_COMPLETE": "bash_complete"},
        capture_output=True,
        text=True,
    )
    assert done.returncode == 2
    (line,) = done.stderr.splitlines()
    assert line.startswith("usdrender-lint: error: _USDRENDER_LINT_COMPLETE is for the shell")
    assert "internal error" not in done.stderr


def test_completion_offers_rules_for_the_selections_and_explain() -> None:
    def complete(words: str) -> set[str]:
        found = _run(
            _USDRENDER_LINT_COMPLETE="bash_complete",
            COMP_WORDS=words,
            COMP_CWORD=str(len(words.split(" ")) - 1),
        )
        return set(found.splitlines())

    assert {"plain,CA001", "plain,CA004"} <= complete("usdrender-lint check --select CA00")
    assert {"plain,ALL", "plain,SE"} <= complete("usdrender-lint check --ignore ")
    # After a comma, the list typed so far stays.
    assert "plain,SE003,camera-unset" in complete("usdrender-lint check --extend-select SE003,cam")
    # explain takes one rule: codes and names, no family.
    explained = complete("usdrender-lint explain camera-u")
    assert explained == {"plain,camera-unset"}
