"""The pre-commit hook, run by the real pre-commit on temporary git repositories.

pre-commit installs the hook repository (a commit of this working tree) into a
fresh virtualenv, usd-core included, which is slow. ``try-repo`` always builds
it in a throwaway store (pre-commit 4.7: ``Store(tempdir)``), so it runs once,
for the failing commit; the other cases run ``pre-commit run`` with the sample
``examples/.pre-commit-config.yaml`` pointed at the same commit, and share one
``PRE_COMMIT_HOME``, hence one hook environment for the module.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from usdrender_lint import __version__

pytestmark = pytest.mark.heavy(seconds=60)

pytest.importorskip("pre_commit")
yaml = pytest.importorskip("yaml")  # PyYAML comes with pre-commit

if shutil.which("git") is None:
    pytest.skip("git is not installed", allow_module_level=True)

REPO = Path(__file__).resolve().parents[2]
HOOK_ID = "usdrender-lint"
FIX_HOOK_ID = "usdrender-lint-fix"
#: The release tag the docs' pre-commit example pins.
TAG = f"v{__version__}"

#: The project's own clean example shot: no finding under any rule.
CLEAN = (REPO / "examples" / "clean_shot" / "shot.usda").read_text(encoding="utf-8")

#: A real defect: an inverted data window (SE003).
BROKEN = """#usda 1.0
def Scope "Render"
{
    def RenderSettings "Settings"
    {
        uniform float4 dataWindowNDC = (0.8, 0, 0.2, 1)
    }
}
"""

#: The camera lives in layout.usda; the data window is fine.
LIGHTING = """#usda 1.0
def Scope "Render"
{
    def RenderSettings "Settings"
    {
        rel camera = </World/cam>
        uniform float4 dataWindowNDC = (0, 0, 1, 1)
    }
}
"""

LAYOUT = """#usda 1.0
def Xform "World"
{
    def Camera "cam"
    {
    }
}
"""

#: Two safe fixes: SE010 (prepend "default") and ST003 (author renderSettingsPrimPath).
FIXABLE = """#usda 1.0
def Scope "Render"
{
    def RenderSettings "Settings"
    {
        uniform token[] includedPurposes = ["render"]
    }
}
"""

SHOT = """#usda 1.0
(
    renderSettingsPrimPath = "/Render/Settings"
    subLayers = [@./lighting.usda@, @./layout.usda@]
)
"""


def _git_env() -> dict[str, str]:
    # Outside a hook's GIT_DIR/GIT_INDEX_FILE, with an identity for commits.
    env = {k: v for k, v in os.environ.items() if not k.startswith(("GIT_", "PRE_COMMIT"))}
    env.update(
        GIT_AUTHOR_NAME="t",
        GIT_AUTHOR_EMAIL="t@example.invalid",
        GIT_COMMITTER_NAME="t",
        GIT_COMMITTER_EMAIL="t@example.invalid",
        GIT_CONFIG_NOSYSTEM="1",
    )
    return env


def _git(cwd: Path, *args: str) -> None:
    subprocess.run(
        ["git", "-c", "init.defaultBranch=main", "-c", "commit.gpgsign=false", *args],
        cwd=cwd,
        env=_git_env(),
        check=True,
        capture_output=True,
    )


@pytest.fixture(scope="module")
def hook_repo(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A clone of this project as a user's pre-commit meets it: a git repository
    whose release tag (the rev the docs pin) is this working tree, as it is now."""
    listed = subprocess.run(
        ["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
        cwd=REPO,
        env=_git_env(),
        check=True,
        capture_output=True,
    ).stdout.decode()
    copy = tmp_path_factory.mktemp("hook-repo")
    for name in filter(None, listed.split("\0")):
        source = REPO / name
        if source.is_file():
            (copy / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(source, copy / name)
    _git(copy, "init", "-q")
    _git(copy, "add", "-A")
    _git(copy, "commit", "-q", "-m", "working tree")
    _git(copy, "tag", TAG)
    return copy


@pytest.fixture(scope="module")
def pre_commit_home(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("pre-commit-home")


def _target_repo(root: Path, committed: dict[str, str], staged: dict[str, str]) -> Path:
    root.mkdir()
    _git(root, "init", "-q")
    for files in (committed, staged):
        for name, text in files.items():
            (root / name).parent.mkdir(parents=True, exist_ok=True)
            (root / name).write_text(text, encoding="utf-8")
        if files:
            _git(root, "add", "--", *files)
        if files is committed and files:
            _git(root, "commit", "-q", "-m", "before")
    return root


def _pre_commit(target: Path, home: Path, *args: str) -> subprocess.CompletedProcess:
    """Run pre-commit in ``target``; hooks see the staged files, as on ``git commit``."""
    env = _git_env()
    env.update(PRE_COMMIT_HOME=str(home), NO_COLOR="1")
    return subprocess.run(
        [sys.executable, "-m", "pre_commit", *args],
        cwd=target,
        env=env,
        capture_output=True,
        text=True,
        timeout=900,
    )


def _run_sample_config(
    target: Path, hook_repo: Path, home: Path, hook_id: str = HOOK_ID, args: list[str] | None = None
) -> subprocess.CompletedProcess:
    """``pre-commit run`` with the sample config (the rev it documents), its repo
    pointed at ``hook_repo`` and its hook ``hook_id`` (with the user's ``args``)."""
    sample = yaml.safe_load((REPO / "examples" / ".pre-commit-config.yaml").read_text())
    [entry] = sample["repos"]
    hook: dict[str, object] = {"id": hook_id}
    if args is not None:
        hook["args"] = args
    entry.update(repo=str(hook_repo), hooks=[hook])
    config = target.parent / f"{target.name}-pre-commit-config.yaml"
    config.write_text(yaml.safe_dump(sample), encoding="utf-8")
    return _pre_commit(target, home, "run", "--config", str(config))


def test_the_manifest_and_the_sample_config_are_valid() -> None:
    for command, path in (
        ("validate-manifest", REPO / ".pre-commit-hooks.yaml"),
        ("validate-config", REPO / "examples" / ".pre-commit-config.yaml"),
    ):
        run = subprocess.run(
            [sys.executable, "-m", "pre_commit", command, str(path)],
            capture_output=True,
            text=True,
        )
        assert run.returncode == 0, run.stdout + run.stderr
    sample = yaml.safe_load((REPO / "examples" / ".pre-commit-config.yaml").read_text())
    assert [h["id"] for repo in sample["repos"] for h in repo["hooks"]] == [HOOK_ID]
    assert [repo["rev"] for repo in sample["repos"]] == [TAG]


def test_the_hooks_match_every_usd_extension_and_nothing_else() -> None:
    hooks = yaml.safe_load((REPO / ".pre-commit-hooks.yaml").read_text())
    assert [(h["id"], h["entry"], h["language"]) for h in hooks] == [
        (HOOK_ID, "usdrender-lint check --force-exclude --pre-commit", "python"),
        (FIX_HOOK_ID, "usdrender-lint check --force-exclude --pre-commit --fix", "python"),
    ]
    assert hooks[0]["files"] == hooks[1]["files"]
    # check --pre-commit reads the staged files by the same pattern.
    from usdrender_lint.cli.check import _HOOK_FILES

    assert hooks[0]["files"] == _HOOK_FILES
    pattern = re.compile(hooks[0]["files"])  # pre-commit matches with re.search
    matched = {n for n in ("a.usd", "a.usda", "a.usdc", "a.usdz", "B.USDA") if pattern.search(n)}
    assert matched == {"a.usd", "a.usda", "a.usdc", "a.usdz", "B.USDA"}
    for name in ("a.usdx", "a.usda.bak", "usda.txt", "a.usd.json"):
        assert not pattern.search(name), name


def test_a_commit_with_a_broken_layer_fails_the_hook(
    tmp_path: Path, hook_repo: Path, pre_commit_home: Path
) -> None:
    target = _target_repo(
        tmp_path / "assets", {}, {"shots/clean.usda": CLEAN, "shots/broken.usda": BROKEN}
    )
    # try-repo at the documented rev, as a user tries the hook before adopting it.
    run = _pre_commit(target, pre_commit_home, "try-repo", str(hook_repo), HOOK_ID, "--ref", TAG)
    output = run.stdout + run.stderr
    assert run.returncode == 1, output
    assert "SE003" in output
    assert "broken.usda" in output
    assert "clean.usda" not in output


def test_a_clean_commit_passes_the_hook(
    tmp_path: Path, hook_repo: Path, pre_commit_home: Path
) -> None:
    # notes.txt would be a stage-open error if the files pattern let it through.
    target = _target_repo(
        tmp_path / "assets", {}, {"shots/clean.usda": CLEAN, "notes.txt": "not a layer\n"}
    )
    run = _run_sample_config(target, hook_repo, pre_commit_home)
    assert run.returncode == 0, run.stdout + run.stderr
    assert re.search(r"usdrender-lint\.+Passed", run.stdout), run.stdout


def test_a_changed_lighting_layer_is_linted_in_its_shot_by_the_hook(
    tmp_path: Path, hook_repo: Path, pre_commit_home: Path
) -> None:
    # Alone, lighting.usda would report its camera (in layout.usda) as missing.
    target = _target_repo(
        tmp_path / "assets",
        {
            # CA003 would fire on the lighting layer alone; SE003 on a real defect.
            ".usdrender-lint.toml": 'roots = ["shots/*/shot.usda"]\nselect = ["CA003", "SE003"]\n',
            "shots/010/shot.usda": SHOT,
            "shots/010/layout.usda": LAYOUT,
        },
        {"shots/010/lighting.usda": LIGHTING},
    )
    run = _run_sample_config(target, hook_repo, pre_commit_home)
    assert run.returncode == 0, run.stdout + run.stderr


def test_the_hooks_leave_out_what_the_configuration_excludes(
    tmp_path: Path, hook_repo: Path, pre_commit_home: Path
) -> None:
    """pre-commit names every staged file; the configuration's exclusions hold
    all the same (--force-exclude), for the fixing hook too."""
    target = _target_repo(
        tmp_path / "assets",
        {".usdrender-lint.toml": 'extend-exclude = ["reference/"]\n'},
        {"shots/clean.usda": CLEAN, "reference/broken.usda": BROKEN, "reference/fix.usda": FIXABLE},
    )
    run = _run_sample_config(target, hook_repo, pre_commit_home)
    assert run.returncode == 0, run.stdout + run.stderr
    fixing = _run_sample_config(target, hook_repo, pre_commit_home, FIX_HOOK_ID)
    assert fixing.returncode == 0, fixing.stdout + fixing.stderr
    assert (target / "reference" / "fix.usda").read_text(encoding="utf-8") == FIXABLE
    # Without the exclusion the same commit fails: the hook did lint what it was given.
    (target / ".usdrender-lint.toml").write_text("")
    _git(target, "add", "-A")  # pre-commit stashes what is not staged
    again = _run_sample_config(target, hook_repo, pre_commit_home)
    assert again.returncode == 1 and "SE003" in again.stdout, again.stdout + again.stderr


def test_a_staged_file_named_like_an_option_is_linted_with_the_users_args(
    tmp_path: Path, hook_repo: Path, pre_commit_home: Path
) -> None:
    """pre-commit appends the staged files after the user's args, with no ``--``:
    ``-x.usda`` is a file all the same, and the args still apply."""
    target = _target_repo(tmp_path / "assets", {}, {"-x.usda": BROKEN, "--fix.usda": CLEAN})
    run = _run_sample_config(target, hook_repo, pre_commit_home, args=["--select", "SE003"])
    assert run.returncode == 1, run.stdout + run.stderr
    assert "-x.usda:6: error SE003" in run.stdout, run.stdout
    assert "1 finding in 2 files" in run.stdout, run.stdout
    assert (target / "-x.usda").read_text(encoding="utf-8") == BROKEN  # not --fix'ed


def test_the_fix_hook_fixes_the_staged_layer_and_then_passes(
    tmp_path: Path, hook_repo: Path, pre_commit_home: Path
) -> None:
    target = _target_repo(tmp_path / "assets", {}, {"shots/fixable.usda": FIXABLE})
    run = _run_sample_config(target, hook_repo, pre_commit_home, FIX_HOOK_ID)
    # pre-commit fails a hook that changed files: the user reviews and stages them.
    assert run.returncode == 1, run.stdout + run.stderr
    assert "files were modified by this hook" in run.stdout, run.stdout
    fixed = (target / "shots" / "fixable.usda").read_text(encoding="utf-8")
    assert '["default", "render"]' in fixed
    assert 'renderSettingsPrimPath = "/Render/Settings"' in fixed
    _git(target, "add", "-A")
    again = _run_sample_config(target, hook_repo, pre_commit_home, FIX_HOOK_ID)
    assert again.returncode == 0, again.stdout + again.stderr


def test_pip_installs_from_the_release_tag(tmp_path: Path, hook_repo: Path) -> None:
    """The docs' ``pip install "git+URL@v0.6.1"``, with the clone as the URL (the
    dependencies are left out: the hook's environment above installs them)."""
    target = tmp_path / "site-packages"
    run = subprocess.run(
        [
            sys.executable, "-m", "pip", "install", "--quiet", "--no-deps",
            "--no-build-isolation", "--target", str(target),
            f"git+{hook_repo.as_uri()}@{TAG}",
        ],
        env=_git_env(),
        capture_output=True,
        text=True,
        timeout=600,
    )  # fmt: skip
    assert run.returncode == 0, run.stderr
    assert (target / f"usdrender_lint-{__version__}.dist-info").is_dir()
    assert (target / "usdrender_lint" / "rules" / "__init__.py").is_file()
