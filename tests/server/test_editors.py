"""A real editor drives the server: headless Neovim (Debian's package) with
the configuration docs/guides/editors.md gives, opening the broken example
shot, and filtering it through `check --fix -`; and the other editors'
snippets of that page say what the server is."""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

pytestmark = pytest.mark.heavy(seconds=29)

REPO = Path(__file__).resolve().parents[2]
GUIDE = REPO / "docs" / "guides" / "editors.md"
BROKEN_SHOT = REPO / "examples" / "broken_shot" / "shot.usda"

#: Run after the guide's snippet: wait for the diagnostics, write them out, quit.
HARNESS = """
local received = vim.wait(90000, function() return #vim.diagnostic.get(0) >= 5 end, 100)
local found = {}
for _, d in ipairs(vim.diagnostic.get(0)) do
  local lsp = (d.user_data or {}).lsp or {}
  table.insert(found, {
    code = d.code or lsp.code, line = d.lnum, col = d.col, severity = d.severity,
    message = d.message, href = (lsp.codeDescription or {}).href,
  })
end
-- The quick fix of CA004, asked for as :lua vim.lsp.buf.code_action() asks
-- (the cursor on the finding, the line's diagnostics as context) and applied.
local fixed = nil
for _, d in ipairs(vim.diagnostic.get(0)) do
  local lsp = (d.user_data or {}).lsp or {}
  if (d.code or lsp.code) == "CA004" then
    vim.api.nvim_win_set_cursor(0, { d.lnum + 1, d.col })
    local params = vim.lsp.util.make_range_params()
    local line_diagnostics = vim.lsp.diagnostic.get_line_diagnostics  -- gone in newer Neovims
    params.context = { diagnostics = line_diagnostics and line_diagnostics() or { {
      range = { start = { line = d.lnum, character = d.col },
                ["end"] = { line = d.end_lnum, character = d.end_col } },
      message = d.message, severity = d.severity, source = d.source,
      code = lsp.code, data = lsp.data,
    } } }
    local answers = vim.lsp.buf_request_sync(0, "textDocument/codeAction", params, 60000)
    for _, answer in pairs(answers or {}) do
      for _, action in ipairs(answer.result or {}) do
        if action.title:find("^Fix CA004") then
          vim.lsp.util.apply_workspace_edit(action.edit, "utf-16")
          fixed = vim.api.nvim_buf_get_lines(0, d.lnum, d.lnum + 1, false)[1]
        end
      end
    end
  end
end
vim.fn.writefile({vim.fn.json_encode({received = received, diagnostics = found, fixed = fixed})},
  os.getenv("USDRENDER_LINT_NVIM_OUT"))
vim.cmd("qa!")
"""


def snippet(heading: str, language: str) -> str:
    """The first ``language`` code block under ``## heading`` in the guide."""
    text = GUIDE.read_text(encoding="utf-8")
    section = text.split(f"\n## {heading}\n", 1)[1].split("\n## ", 1)[0]
    match = re.search(rf"```{language}\n(.*?)```", section, re.DOTALL)
    assert match, f"no {language} block under {heading}"
    return match.group(1)


def run_neovim(tmp_path: Path, harness: str, files: tuple[Path, ...] = (), **env: str) -> dict:
    """Run headless Neovim with the guide's snippet as its init and ``harness``
    (Lua that writes what it saw as JSON to $USDRENDER_LINT_NVIM_OUT); ``env``:
    more variables the harness reads. Skips when Neovim is not installed."""
    nvim = shutil.which("nvim")
    if nvim is None:
        pytest.skip("Neovim is not installed (apt-get install neovim): the editor test is skipped")
    (tmp_path / "init.lua").write_text(snippet("Neovim", "lua"))
    (tmp_path / "harness.lua").write_text(harness)
    out = tmp_path / "seen.json"
    # The snippet runs `usdrender-lint server`: the one beside this Python.
    environment = {
        **os.environ,
        "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ.get('PATH', '')}",
        "USDRENDER_LINT_NVIM_OUT": str(out),
        "XDG_STATE_HOME": str(tmp_path / "state"),
        "XDG_DATA_HOME": str(tmp_path / "data"),
        "XDG_CONFIG_HOME": str(tmp_path / "config"),
        **env,
    }
    result = subprocess.run(
        [nvim, "--headless", "-i", "NONE", "-u", str(tmp_path / "init.lua"),
         *map(str, files), "-c", f"luafile {tmp_path / 'harness.lua'}"],
        cwd=tmp_path, env=environment, capture_output=True, text=True, timeout=180,
    )  # fmt: skip
    assert out.exists(), result.stderr
    seen: dict = json.loads(out.read_text())
    print(json.dumps(seen, indent=1))  # the test's output: what Neovim received
    return seen


def test_neovim_shows_the_findings_of_a_broken_shot(tmp_path: Path):
    shot = tmp_path / "shot.usda"
    shutil.copy(BROKEN_SHOT, shot)
    seen = run_neovim(tmp_path, HARNESS, (shot,))
    assert seen["received"] is True
    found = {(d["code"], d["line"] + 1) for d in seen["diagnostics"]}
    assert found == {("CA004", 32), ("SE007", 37), ("CA003", 51), ("SE003", 54), ("PR004", 59)}
    camera = next(d for d in seen["diagnostics"] if d["code"] == "CA004")
    assert camera["col"] == 8 and camera["severity"] == 1
    assert camera["href"].endswith("/reference/rules/CA004-camera-target-not-camera/")
    # Its quick fix, applied by Neovim to the buffer: the line --fix writes.
    assert seen["fixed"] == "        rel camera = </World/camRig/shotCam>"


def test_neovim_filters_a_buffer_through_check_fix_stdin(tmp_path: Path):
    """The guide's `check --fix -` as an editor runs it (a Neovim filter over the
    whole buffer): the buffer becomes what `check --fix` writes into the file,
    and the file itself is not touched."""
    nvim = shutil.which("nvim")
    if nvim is None:
        pytest.skip("Neovim is not installed (apt-get install neovim): the editor test is skipped")
    shot, expected = tmp_path / "shot.usda", tmp_path / "expected.usda"
    shutil.copy(BROKEN_SHOT, shot)
    shutil.copy(BROKEN_SHOT, expected)
    lint = [sys.executable, "-m", "usdrender_lint", "check", "--isolated", "--no-cache"]
    subprocess.run([*lint, "--fix", str(expected)], capture_output=True, timeout=120, check=False)
    command = " ".join([*lint, "--fix", "-", "--stdin-filename", "%"])
    subprocess.run(
        [nvim, "--headless", "-u", "NONE", "-c", f"silent %!{command}", "-c",
         f"w! {tmp_path / 'buffer.usda'}", "-c", "qa!", str(shot)],
        capture_output=True, timeout=120, check=False, cwd=tmp_path,
    )  # fmt: skip
    assert (tmp_path / "buffer.usda").read_bytes() == expected.read_bytes()
    assert expected.read_bytes() != BROKEN_SHOT.read_bytes()  # there were fixes
    assert shot.read_bytes() == BROKEN_SHOT.read_bytes()


#: Opens a document whose lint hangs USD, then another: the seconds until the
#: second one's diagnostics.
HANGING_HARNESS = """
vim.cmd("edit " .. os.getenv("USDRENDER_LINT_HANGS"))
vim.wait(5000, function() return false end, 100)  -- its lint has started, and hangs
local asked = vim.loop.hrtime()
vim.cmd("edit " .. os.getenv("USDRENDER_LINT_FINE"))
local buffer = vim.api.nvim_get_current_buf()
local received = vim.wait(60000, function() return #vim.diagnostic.get(buffer) >= 1 end, 20)
local seconds = (vim.loop.hrtime() - asked) / 1e9
vim.fn.writefile({vim.fn.json_encode({received = received, seconds = seconds})},
  os.getenv("USDRENDER_LINT_NVIM_OUT"))
vim.cmd("qa!")
"""


def test_neovim_gets_a_document_s_findings_while_another_hangs_usd(tmp_path: Path):
    """With the guide's snippet (the time-out 120 s): the second document's
    findings waited for the first's time-out."""
    from cli_support import hanging_stage

    fine = tmp_path / "fine.usda"
    fine.write_text('#usda 1.0\ndef RenderSettings "S"\n{\n    int2 resolution = (0, 1)\n}\n')
    seen = run_neovim(
        tmp_path,
        HANGING_HARNESS,
        USDRENDER_LINT_HANGS=str(hanging_stage(tmp_path)),
        USDRENDER_LINT_FINE=str(fine),
    )
    assert seen["received"] is True and seen["seconds"] < 30


#: Opens a shot, edits it to sublayer a FIFO (USD hangs on it), then asks for
#: the older text's ST003 fix as :lua vim.lsp.buf.code_action() asks: whether
#: and how soon the answer came.
HUNG_ACTION_HARNESS = """
vim.cmd("edit " .. os.getenv("USDRENDER_LINT_SHOT"))
local buffer = vim.api.nvim_get_current_buf()
local linted = vim.wait(90000, function() return #vim.diagnostic.get(buffer) >= 1 end, 50)
local st003 = nil
for _, d in ipairs(vim.diagnostic.get(buffer)) do
  local lsp = (d.user_data or {}).lsp or {}
  if (d.code or lsp.code) == "ST003" then
    st003 = {
      range = { start = { line = d.lnum, character = d.col },
                ["end"] = { line = d.end_lnum, character = d.end_col } },
      message = d.message, severity = d.severity, source = d.source,
      code = lsp.code, data = lsp.data,
    }
  end
end
vim.api.nvim_buf_set_lines(buffer, 0, 1, false,
  { "#usda 1.0", "(", "    subLayers = [@`\\"./pipe.usda\\"`@]", ")" })
vim.wait(3000, function() return false end, 100)  -- its lint starts, and hangs
local asked = vim.loop.hrtime()
local answers = vim.lsp.buf_request_sync(buffer, "textDocument/codeAction", {
  textDocument = vim.lsp.util.make_text_document_params(buffer),
  range = st003 and st003.range, context = { diagnostics = { st003 } },
}, 60000)
local seconds = (vim.loop.hrtime() - asked) / 1e9
vim.fn.writefile({vim.fn.json_encode({
  linted = linted, st003 = st003 ~= nil, answered = answers ~= nil, seconds = seconds,
})}, os.getenv("USDRENDER_LINT_NVIM_OUT"))
vim.cmd("qa!")
"""


def test_neovim_gets_an_answer_to_a_code_action_on_a_document_that_hangs_usd(tmp_path: Path):
    """With the guide's snippet (the time-out 120 s): the fix composed the
    stage USD hangs on, and Neovim's request had no answer within a minute."""
    os.mkfifo(tmp_path / "pipe.usda")
    shot = tmp_path / "shot.usda"
    shot.write_text('#usda 1.0\ndef RenderSettings "S"\n{\n    int2 resolution = (0, 1)\n}\n')
    seen = run_neovim(tmp_path, HUNG_ACTION_HARNESS, USDRENDER_LINT_SHOT=str(shot))
    assert seen["linted"] is True and seen["st003"] is True
    assert seen["answered"] is True and seen["seconds"] < 10


#: Opens the shot, then its sublayer, and edits the sublayer without saving:
#: whether the shot's finding on the edit (SE011) comes, and on which line.
LINKED_LAYER_HARNESS = """
vim.cmd("edit " .. os.getenv("USDRENDER_LINT_SHOT"))
local shot = vim.api.nvim_get_current_buf()
local linted = vim.wait(90000, function() return #vim.diagnostic.get(shot) >= 1 end, 50)
vim.cmd("edit " .. os.getenv("USDRENDER_LINT_LAYER"))
local layer = vim.api.nvim_get_current_buf()
vim.wait(3000, function() return false end, 100)  -- opened and linted
local line = vim.fn.search("materialBindingPurposes") - 1
vim.api.nvim_buf_set_lines(layer, line, line + 1, false,
  { '        uniform token[] materialBindingPurposes = ["full", "bogus"]' })
local function se011()
  for _, d in ipairs(vim.diagnostic.get(layer)) do
    local lsp = (d.user_data or {}).lsp or {}
    if (d.code or lsp.code) == "SE011" then return d.lnum end
  end
  return nil
end
local shown = vim.wait(30000, function() return se011() ~= nil end, 50)
vim.fn.writefile({vim.fn.json_encode({linted = linted, shown = shown, line = se011()})},
  os.getenv("USDRENDER_LINT_NVIM_OUT"))
vim.cmd("qa!")
"""


def test_neovim_composes_a_sublayer_s_unsaved_text_across_a_symlink(tmp_path: Path):
    """The shot sublayers ``./assets/layer.usda``, ``assets`` a symlink to the
    library; Neovim names the buffer of that file by its resolved path. The
    shot's stage composed the saved file, and the edit's finding never came."""
    library = tmp_path / "library"
    library.mkdir()
    (tmp_path / "assets").symlink_to(library, target_is_directory=True)
    shot = tmp_path / "shot.usda"
    shot.write_text(
        '#usda 1.0\n(\n    subLayers = [@./assets/layer.usda@]\n)\ndef Scope "Render"\n{\n'
        '    def RenderSettings "rs"\n    {\n    }\n}\n'
    )
    (library / "layer.usda").write_text(
        '#usda 1.0\nover "Render"\n{\n    over "rs"\n    {\n'
        '        uniform token[] materialBindingPurposes = ["full", "preview"]\n    }\n}\n'
    )
    seen = run_neovim(
        tmp_path,
        LINKED_LAYER_HARNESS,
        USDRENDER_LINT_SHOT=str(shot),
        USDRENDER_LINT_LAYER=str(tmp_path / "assets" / "layer.usda"),
    )
    assert seen == {"linted": True, "shown": True, "line": 5}


def test_the_helix_snippet_runs_the_server():
    config = tomllib.loads(snippet("Helix", "toml"))
    server = config["language-server"]["usdrender-lint"]
    assert [server["command"], *server["args"]] == ["usdrender-lint", "server"]
    (language,) = config["language"]
    assert language["language-servers"] == ["usdrender-lint"]
    assert set(language["file-types"]) == {"usda", "usd"}


def test_the_vs_code_snippet_runs_the_server():
    settings = json.loads(snippet("VS Code", "json"))
    command = [settings["glspc.server.command"], *settings["glspc.server.commandArguments"]]
    assert command == ["usdrender-lint", "server"]
    assert settings["files.associations"]["*.usda"] in settings["glspc.server.languageId"]


def test_the_eglot_snippet_runs_the_server():
    elisp = snippet("Emacs (eglot)", "elisp")
    assert elisp.count("(") == elisp.count(")")
    assert '(usda-mode "usdrender-lint" "server")' in elisp
    # The mode's pattern matches both text extensions (Emacs regexp: \\' ends the name).
    pattern = re.search(r'"(\\\\\.usda\?\\\\\')"', elisp)
    assert pattern is not None
    as_python = pattern.group(1).replace("\\\\", "\\").replace("\\'", "$")
    assert re.search(as_python, "shot.usda") and re.search(as_python, "shot.usd")
    assert not re.search(as_python, "shot.usdc")
