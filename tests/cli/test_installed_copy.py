"""A plain (non-editable) install works with the repository root as the current
directory: the command, ``python -m``, the Python API, fixes, roots, a worker
pool, a progress bar and the UsdValidation plugin.

From the clone's root, Python imports ./usdrender_lint (the source tree) before
the installed copy, and worker processes started by a forkserver do too; the
built-in rules sit beside the source tree in ./rules. An editable install hides
all of it, so this builds a wheel from a copy of the tree and installs it into
a fresh virtual environment that borrows only the test environment's
dependencies (usd-core, click, rich).
"""

from __future__ import annotations

import json
import os
import pty
import shutil
import subprocess
import sys
import sysconfig
import textwrap
from dataclasses import dataclass
from pathlib import Path

import pytest

pytestmark = pytest.mark.heavy(seconds=16)

REPO = Path(__file__).resolve().parents[2]
FIXTURES = REPO / "tests" / "rules"
CA004_RIG = FIXTURES / "CA004_camera_target_not_camera" / "fail_rig.usda"
#: What the source tree must never make a run say.
IMPORT_FAILURE = "No module named"
_IGNORED = shutil.ignore_patterns(
    ".git", ".venv*", "build", "dist", "*.egg-info", "__pycache__", ".pytest_cache",
    ".ruff_cache", ".mypy_cache", ".hypothesis", ".usdrender_lint_cache", "benchmarks",
)  # fmt: skip


@dataclass(frozen=True)
class Installed:
    bin: Path

    @property
    def command(self) -> str:
        return str(self.bin / "usdrender-lint")

    @property
    def python(self) -> str:
        return str(self.bin / "python")


@pytest.fixture(scope="module")
def installed(tmp_path_factory: pytest.TempPathFactory) -> Installed:
    work = tmp_path_factory.mktemp("installed")
    source = work / "source"
    shutil.copytree(REPO, source, ignore=_IGNORED)
    built = subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "-q",
         "-w", str(work / "wheels"), str(source)],
        capture_output=True, text=True, timeout=600,
    )  # fmt: skip
    if built.returncode != 0:
        pytest.skip(f"cannot build a wheel here: {built.stderr.strip().splitlines()[-1:]}")
    (wheel,) = (work / "wheels").glob("usdrender_lint-*.whl")
    venv = work / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(venv)], check=True)
    python = venv / "bin" / "python"
    purelib = subprocess.run(
        [str(python), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
        capture_output=True, text=True, check=True,
    ).stdout.strip()  # fmt: skip
    # A path line in a .pth adds the test environment's packages, not its .pth
    # files: the editable install's finder stays out of this environment.
    (Path(purelib) / "test_dependencies.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")
    subprocess.run(
        [sys.executable, "-m", "pip", "--python", str(python), "install", "-q", "--no-deps",
         str(wheel)],
        check=True, capture_output=True, timeout=600,
    )  # fmt: skip
    return Installed(venv / "bin")


def _run(*argv: str, cwd: Path = REPO, **kwargs: object) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if not k.startswith(("PYTHON", "VIRTUAL_ENV"))}
    env.update(kwargs.pop("env", None) or {})  # type: ignore[call-overload]
    kwargs.setdefault("stderr", subprocess.PIPE)
    done = subprocess.run(
        list(argv), cwd=cwd, env=env, stdout=subprocess.PIPE, text=True, timeout=600, **kwargs
    )  # type: ignore[call-overload]
    said = done.stdout + (done.stderr or "")
    assert IMPORT_FAILURE not in said and "Traceback" not in said, said
    return done


def _codes(report_json: str) -> set[str]:
    return {f["code"] for entry in json.loads(report_json)["files"] for f in entry["findings"]}


def test_the_command_and_python_m_lint_from_the_repository_root(installed: Installed) -> None:
    done = _run(installed.command, "check", "--format", "json", "examples/")
    assert done.returncode == 1
    assert {"ST001", "CA004", "SE003", "PR004"} <= _codes(done.stdout)
    done = _run(installed.python, "-m", "usdrender_lint", "check", "examples/clean_shot")
    assert done.returncode == 0, done.stdout + done.stderr


def test_workers_lint_from_the_repository_root(installed: Installed) -> None:
    # --jobs 2 starts worker processes; --timeout makes even one file use them.
    args = ["check", "--format", "json", "--jobs", "2", "--timeout", "60", "examples/"]
    done = _run(installed.command, *args)
    assert done.returncode == 1
    assert "CA004" in _codes(done.stdout)


def test_the_python_api_from_the_repository_root(installed: Installed) -> None:
    script = textwrap.dedent(
        """
        import json, usdrender_lint
        report = usdrender_lint.lint_file("examples/broken_shot/shot.usda")
        print(json.dumps(sorted({f.code for f in report.findings})))
        """
    )
    done = _run(installed.python, "-c", script)
    assert done.returncode == 0, done.stderr
    assert "CA004" in json.loads(done.stdout)


def test_fix_and_diff_from_the_repository_root(installed: Installed, tmp_path: Path) -> None:
    shot = tmp_path / "shot.usda"
    lines = CA004_RIG.read_text().splitlines(keepends=True)
    shot.write_text(lines[0] + "".join(line for line in lines[1:] if not line.startswith("#")))
    before = shot.read_text()
    done = _run(installed.command, "check", "--diff", "--select", "CA004", str(shot))
    assert "1 fix would be applied" in done.stderr, done.stderr
    assert done.returncode == 1  # a fix is pending
    # The shot is outside the current directory: the patch names it as given.
    assert done.stdout.startswith(f"--- {shot}\n+++ {shot}\n")
    assert shot.read_text() == before  # --diff writes nothing
    done = _run(installed.command, "check", "--fix", "--select", "CA004", str(shot))
    assert done.returncode == 0, done.stdout + done.stderr
    assert shot.read_text() != before
    done = _run(installed.command, "check", "--format", "json", "--select", "CA004", str(shot))
    assert done.returncode == 0 and _codes(done.stdout) == set()


def test_roots_from_the_repository_root(installed: Installed, tmp_path: Path) -> None:
    (tmp_path / "lighting.usda").write_text(
        '#usda 1.0\ndef Scope "Render"\n{\n    def RenderSettings "Settings"\n    {\n'
        "        rel camera = </World/cam>\n        uniform float4 dataWindowNDC = (1, 0, 0, 1)\n"
        "    }\n}\n"
    )
    (tmp_path / "shot.usda").write_text(
        '#usda 1.0\n(\n    subLayers = [@./lighting.usda@]\n)\ndef Xform "World"\n{\n'
        '    def Camera "cam"\n    {\n    }\n}\n'
    )
    config = tmp_path / ".usdrender-lint.toml"
    config.write_text('roots = ["shot.usda"]\n')
    args = ["check", "--format", "json", "--config", str(config), str(tmp_path / "lighting.usda")]
    done = _run(installed.command, *args)
    codes = _codes(done.stdout)
    assert "SE003" in codes and "CA003" not in codes  # the camera is found in its shot


def test_a_progress_bar_run_from_the_repository_root(installed: Installed, tmp_path: Path) -> None:
    for index in range(25):  # a bar is drawn for runs of more than 20 files
        shutil.copy(CA004_RIG, tmp_path / f"shot_{index:02}.usda")
    controller, terminal = pty.openpty()
    try:
        done = _run(installed.command, "check", "--format", "json", str(tmp_path), stderr=terminal)
    finally:
        os.close(terminal)
        os.close(controller)
    assert done.returncode == 1
    assert len(json.loads(done.stdout)["files"]) == 25


def test_the_usdvalidation_plugin_from_the_repository_root(installed: Installed) -> None:
    plugin_dir = _run(installed.command, "plugin-path").stdout.strip()
    script = textwrap.dedent(
        """
        import json
        from pxr import Usd, UsdValidation
        registry = UsdValidation.ValidationRegistry()
        metadata = registry.GetValidatorMetadataForKeyword("usdRenderLint")
        validators = [registry.GetOrLoadValidatorByName(m.name) for m in metadata]
        context = UsdValidation.ValidationContext([v for v in validators if v is not None])
        stage = Usd.Stage.Open("examples/broken_shot/shot.usda")
        print(json.dumps(sorted({e.GetName() for e in context.Validate(stage)})))
        """
    )
    done = _run(installed.python, "-c", script, env={"PXR_PLUGINPATH_NAME": plugin_dir})
    assert done.returncode == 0, done.stderr
    assert "CA004" in json.loads(done.stdout)
