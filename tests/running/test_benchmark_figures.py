"""benchmarks/run.py's figures: the ratios it prints against a baseline."""

from __future__ import annotations

from pathlib import Path

from bench_support import load_script

run = load_script("run")


def _series(label: str, seconds: list[float]):
    series = run.Series(label, ["true"])
    series.samples = [run.Sample(s, 1024, s) for s in seconds]
    return series


def test_a_paired_ratio_is_the_median_of_each_rounds_ratio() -> None:
    # The machine slows down over the run: each round's ratio stays 1.2.
    bare = _series("bare", [1.0, 2.0, 4.0])
    check = _series("check", [1.2, 2.4, 4.8])
    assert round(run.paired(check, bare), 6) == 1.2
    assert round(check.median() / bare.median(), 6) == 1.2
    # A slow round of one side alone moves the paired figure by one round only.
    check = _series("check", [1.2, 2.4, 40.0])
    assert round(run.paired(check, bare), 6) == 1.2
    assert "paired 1.20x" in run.row(check, bare)


def _empty_shots(folder: Path, *how: str) -> Path:
    """In place of run.ensure: ``--count`` empty gate shots."""
    folder.mkdir()
    for i in range(int(how[how.index("--count") + 1])):
        (folder / f"gate_{i:04d}.usda").write_text("#usda 1.0\n")
    return folder


def _gate_count(argv: list[str]) -> int:
    """In place of valgrind's count of a gate process."""
    if "--timeout" in argv:  # the lint of a folder: 300M to start, 40M a shot
        return 300_000_000 + 40_000_000 * len(list(Path(argv[-1]).glob("gate_*.usda")))
    # The floor over the files: 200M to start, 25M a shot.
    return 200_000_000 + 25_000_000 * sum(arg.endswith(".usda") for arg in argv)


def test_the_gate_in_instructions_is_what_one_more_shot_costs(tmp_path, monkeypatch) -> None:
    def instructions(argv, env=None):
        assert env is not None and env["PYTHONHASHSEED"] == "0"
        return _gate_count(argv)

    monkeypatch.setattr(run, "ensure", _empty_shots)
    monkeypatch.setattr(run, "instructions", instructions)
    # Start-up cancels out (22 shots less 2): 40M against 25M a shot.
    assert run.gate_instructions(tmp_path) == {"gate_shot_instructions": 40 / 25}
    assert run._goal("gate_shot_instructions") == ("<=", 2.0)


def test_each_gate_count_is_the_median_of_its_runs(tmp_path, monkeypatch) -> None:
    # valgrind's counts of the same process move: the first count of the lint of 22
    # shots is 9M high, the second of the floor over them 9M low. The medians leave
    # the figure as if neither were (a first count, a max or a min would not).
    runs: dict[tuple[str, ...], int] = {}
    off = {(True, 1): 9_000_000, (False, 2): -9_000_000}

    def instructions(argv, env=None):
        runs[tuple(argv)] = runs.get(tuple(argv), 0) + 1
        over_22 = "gate_22" in Path(argv[-1]).parts  # the lint's folder, the floor's last shot
        moved = off.get(("--timeout" in argv, runs[tuple(argv)]), 0) if over_22 else 0
        return _gate_count(argv) + moved

    monkeypatch.setattr(run, "ensure", _empty_shots)
    monkeypatch.setattr(run, "instructions", instructions)
    assert run.gate_instructions(tmp_path) == {"gate_shot_instructions": 40 / 25}
    # Each of the four processes counted GATE_COUNTS times (the lint of 2 shots once more,
    # the run that writes the bytecode).
    assert sorted(runs.values()) == [run.GATE_COUNTS] * 3 + [run.GATE_COUNTS + 1]


def test_beyond_start_up_is_what_one_more_shot_costs_from_the_fewest_and_most_shots() -> None:
    # --jobs 1: 0.2 s to start, 5 ms a shot; the floor 0.1 s and 2 ms. A middle run
    # that a slow spell made dearer is not read.
    runs = {
        200: (0.2 + 200 * 0.005, 0.1 + 200 * 0.002),
        500: (9.0, 9.0),
        1000: (0.2 + 1000 * 0.005, 0.1 + 1000 * 0.002),
    }
    lint, floor, lint_fixed, floor_fixed = run.beyond_start_up(runs)
    assert (round(lint, 9), round(floor, 9)) == (0.005, 0.002)
    assert (round(lint_fixed, 9), round(floor_fixed, 9)) == (0.2, 0.1)
    # The whole runs' ratios (2.33x, 2.43x) approach the per-shot one (2.5x).
    assert runs[200][0] / runs[200][1] < runs[1000][0] / runs[1000][1] < lint / floor


def test_a_gate_run_that_a_slow_spell_distorted_says_so_and_meets_no_goal(
    tmp_path, monkeypatch, capsys
) -> None:
    # The floor's one process took 2.5 s where its two took 1.0 s: faster than two
    # processes can make it on two CPUs, so the one-process rounds were slowed and
    # --jobs 1 against them (1.2x) would meet its goal falsely.
    seconds = {
        "open+traverse 200 shots, 1 process": 2.5,
        "open+traverse 200 shots, 2 processes": 1.0,
        "check --jobs 1 200 shots": 3.0,
        "check --jobs 2 200 shots": 1.8,
        "check --jobs 1, 1 shot": 0.2,
    }

    def measure(series, rounds):
        for s in series:
            s.samples = [run.Sample(seconds[s.label], 1024, seconds[s.label])] * rounds

    monkeypatch.setattr(run, "ensure", _empty_shots)
    monkeypatch.setattr(run, "measure", measure)
    monkeypatch.setattr(run.os, "cpu_count", lambda: 2)
    figures, medians = run.gate(tmp_path, 200, 3)
    assert figures == {
        "gate_200_jobs1_disturbed": 3.0 / 2.5,
        "gate_200_speedup": 3.0 / 1.8,
        "gate_200_rss": 1.0,
    }
    assert medians == (3.0, 2.5)
    assert "disturbed: the floor: 2.50x as fast with two processes" in capsys.readouterr().out
    assert run._goal("gate_200_jobs1_disturbed") is None
    assert run.verdict(figures) is False  # the speed-up's own goal (>= 1.7) still judges
    assert "gate_200_jobs1_disturbed     1.20\n" in capsys.readouterr().out
    # The lint's own one-process rounds slowed: both figures that read them meet no goal.
    seconds.update({"open+traverse 200 shots, 1 process": 1.5, "check --jobs 1 200 shots": 4.0})
    (tmp_path / "again").mkdir()
    figures, _ = run.gate(tmp_path / "again", 200, 3)
    assert sorted(figures) == [
        "gate_200_jobs1_disturbed",
        "gate_200_rss",
        "gate_200_speedup_disturbed",
    ]


def test_a_gate_case_whose_rounds_a_slow_spell_spread_meets_no_goal(
    tmp_path, monkeypatch, capsys
) -> None:
    # The eleventh session's third run: the floor's one process took 0.56 s in two
    # rounds and 0.69 s in three, so --jobs 1 against its median (1.25 / 0.69 = 1.81x)
    # met its goal by the spell alone, while two processes stayed within what they give.
    rounds = {
        "open+traverse 200 shots, 1 process": [0.56, 0.69, 0.56, 0.69, 0.69],
        "open+traverse 200 shots, 2 processes": [0.40] * 5,
        "check --jobs 1 200 shots": [1.25] * 5,
        "check --jobs 2 200 shots": [0.70] * 5,
        "check --jobs 1, 1 shot": [0.2] * 5,
    }

    def measure(series, count):
        for s in series:
            s.samples = [run.Sample(seconds, 1024, seconds) for seconds in rounds[s.label]]

    monkeypatch.setattr(run, "ensure", _empty_shots)
    monkeypatch.setattr(run, "measure", measure)
    monkeypatch.setattr(run.os, "cpu_count", lambda: 2)
    figures, _ = run.gate(tmp_path, 200, 5)
    assert sorted(figures) == ["gate_200_jobs1_disturbed", "gate_200_rss", "gate_200_speedup"]
    assert figures["gate_200_jobs1_disturbed"] == 1.25 / 0.69
    out = capsys.readouterr().out
    assert "disturbed: the floor: its median round took 1.23x its fastest (more than 1.10x)" in out
    # The floor steady, the lint's two processes slowed: the speed-up alone meets no goal.
    rounds["open+traverse 200 shots, 1 process"] = [0.56] * 5
    rounds["check --jobs 2 200 shots"] = [0.70, 0.80, 0.80, 0.70, 0.80]
    (tmp_path / "again").mkdir()
    figures, _ = run.gate(tmp_path / "again", 200, 5)
    assert sorted(figures) == ["gate_200_jobs1", "gate_200_rss", "gate_200_speedup_disturbed"]
    assert "the lint's two processes: its median round took 1.14x" in capsys.readouterr().out


def test_rounds_within_the_spread_limit_are_not_a_slow_spell() -> None:
    def series(*seconds: float) -> run.Series:
        return run.Series("case", [], samples=[run.Sample(s, 1024, s) for s in seconds])

    steady = series(1.00, 1.05, 1.08, 1.09, 1.10)  # the median 1.08x the fastest
    slowed = series(1.00, 1.00, 1.12, 1.12, 1.12)
    assert run.slow_spells({"steady": steady, "slowed": slowed}).keys() == {"slowed"}
    assert run.slow_spells({"steady": steady}, limit=1.05).keys() == {"steady"}


def test_what_two_processes_cannot_do_marks_a_run_disturbed() -> None:
    speedups = {"the floor": 1.9, "the lint": 2.2}
    assert list(run.impossible_speedups(speedups, cpus=2)) == ["the lint"]
    assert list(run.impossible_speedups(speedups, cpus=1)) == ["the floor", "the lint"]
    assert list(run.impossible_speedups(speedups, cpus=8)) == ["the lint"]
    assert run.negative_start_ups({"the lint": 0.2, "the floor": -0.21}) == [
        "the floor: a start-up of -0.21 s: a slow spell hit its run of the most shots"
    ]


def test_the_gate_prints_the_speed_up_two_busy_cores_allow(tmp_path, monkeypatch, capsys) -> None:
    # --jobs 1 took 5 s of wall time beside USD's threads; --jobs 2 spent
    # 7 s of CPU: two cores never idle take 3.5 s, so it can be at most 1.43x as fast,
    # and at 4 s (1.25x) it reaches 88% of that.
    seconds = {
        "open+traverse 200 shots, 1 process": 3.0,
        "open+traverse 200 shots, 2 processes": 1.7,
        "check --jobs 1 200 shots": 5.0,
        "check --jobs 2 200 shots": 4.0,
        "check --jobs 1, 1 shot": 0.2,
    }

    def measure(series, rounds):
        for s in series:
            cpu = 7.0 if s.label == "check --jobs 2 200 shots" else seconds[s.label]
            s.samples = [run.Sample(seconds[s.label], 1024, cpu)] * rounds

    monkeypatch.setattr(run, "ensure", _empty_shots)
    monkeypatch.setattr(run, "measure", measure)
    monkeypatch.setattr(run.os, "cpu_count", lambda: 2)
    run.gate(tmp_path, 200, 3)
    assert round(run.two_core_ceiling(5.0, 7.0), 4) == round(5.0 / 3.5, 4)
    out = capsys.readouterr().out
    assert "--jobs 2's CPU time (7.00 s) make it at most 1.43x --jobs 1: it reaches 88%" in out


def test_the_gate_on_crate_shots_is_shown_and_judged_by_no_goal(
    tmp_path, monkeypatch, capsys
) -> None:
    asked = []

    def crate_shots(folder: Path, *how: str) -> Path:
        asked.append(how)
        folder.mkdir()
        for i in range(int(how[how.index("--count") + 1])):
            (folder / f"gate_{i:04d}.usdc").write_bytes(b"PXR-USDC")
        return folder

    def measure(series, rounds):
        for s in series:
            assert all(not arg.endswith(".usda") for arg in s.argv)
            s.samples = [run.Sample(1.0, 1024, 1.0)] * rounds

    monkeypatch.setattr(run, "ensure", crate_shots)
    monkeypatch.setattr(run, "measure", measure)
    figures, _ = run.gate(tmp_path, 4, 3, "usdc")
    assert figures == {}  # the goals are the text shots'
    assert asked == [("gate", "--count", "4", "--format", "usdc")]
    assert "CI gate: 4 shots (.usdc" in capsys.readouterr().out


def test_the_crate_gate_shots_are_the_text_shots(tmp_path) -> None:
    import usdrender_lint

    generate = load_script("generate")
    text = generate.generate_gate(tmp_path / "usda", 2)
    crate = generate.generate_gate(tmp_path / "usdc", 2, fmt="usdc")
    assert [p.suffix for p in crate] == [".usdc", ".usdc"]
    assert crate[0].read_bytes().startswith(b"PXR-USDC")

    def found(path: Path) -> list[tuple[str, str | None, str]]:
        report = usdrender_lint.lint_file(path, config={"select": ["ALL"]})
        return sorted((f.code, f.location.path, f.message) for f in report.findings)

    assert found(text[0])  # the first of every ten shots has defects
    for usda, usdc in zip(text, crate, strict=True):
        assert found(usda) == found(usdc)


#: Part of ``callgrind_annotate --inclusive=yes``'s listing of a process that built
#: USD's trace collector (the namespace and library paths shortened).
_COLLECTOR = "???:pxrInternal_v0_25_11__pxrReserved__::TraceCollector::"
_ANNOTATED_LISTING = "\n".join(
    [
        "855,412,300 (100.0%)  PROGRAM TOTALS",
        "Ir                   file:function",
        "855,412,300 (100.0%)  ???:0x0000000000001100 [/usr/lib/ld.so]",
        f" 31,250,000 ( 3.65%)  {_COLLECTOR}TraceCollector() [/x/libusd_ms.so]",
        f" 30,900,000 ( 3.61%)  {_COLLECTOR}_MeasureScopeOverhead() [/x/libusd_ms.so]",
        f" 30,100,000 ( 3.52%)  {_COLLECTOR}_MeasureScopeOverhead()::{{lambda()#1}}::"
        "operator()() const [/x/libusd_ms.so]",
        f"  1,000,000 ( 0.12%)  {_COLLECTOR}_MeasureScopeOverhead()'2 [/x/libusd_ms.so]",
    ]
)


def test_a_count_leaves_out_the_loop_usd_times_itself_with() -> None:
    # The function's own inclusive count: not its caller's, its lambda's or a recursion's.
    assert run.clock_bound(_ANNOTATED_LISTING) == 30_900_000
    # A process that never built the trace collector (no pxr import) has nothing to leave out.
    assert run.clock_bound(_ANNOTATED_LISTING.split(" 31,250,000")[0]) == 0


def test_the_hosts_case_validates_with_every_validator_and_is_judged_by_no_goal(
    tmp_path, monkeypatch, capsys
) -> None:
    import os
    import subprocess
    import sys

    from usdrender_lint.usdplugin import plugin_dir

    # The script the case times validates a broken shot with the plugin's validators,
    # and refuses to time a run in which none registered.
    shot = Path(__file__).resolve().parents[2] / "examples" / "broken_shot" / "shot.usda"
    counting = run.VALIDATE_ALL.replace(
        "    context.Validate(Usd.Stage.Open(f))",
        "    print(len(context.Validate(Usd.Stage.Open(f))))",
    )
    env = dict(os.environ, PXR_PLUGINPATH_NAME=str(plugin_dir()))
    done = subprocess.run(
        [sys.executable, "-c", counting, str(shot)], capture_output=True, text=True, env=env
    )
    assert done.returncode == 0, done.stderr
    assert int(done.stdout.split()[-1]) > 0
    unregistered = dict(os.environ, PXR_PLUGINPATH_NAME=str(tmp_path))
    refused = subprocess.run(
        [sys.executable, "-c", run.VALIDATE_ALL, str(shot)], capture_output=True, env=unregistered
    )
    assert refused.returncode != 0

    seconds = {"open+traverse 4 shots": 1.0, "check --jobs 1 4 shots": 2.0}

    def measure(series, rounds):
        for s in series:
            s.samples = [run.Sample(seconds.get(s.label, 5.0), 1024, 1.0)] * rounds

    monkeypatch.setattr(run, "ensure", _empty_shots)
    monkeypatch.setattr(run, "measure", measure)
    figures = run.hosts(tmp_path, 4, 3)
    assert figures == {"hosts_4_usdvalidation_vs_check": 2.5}
    assert run._goal("hosts_4_usdvalidation_vs_check") is None
    assert "UsdValidation 2.50x check --jobs 1" in capsys.readouterr().out
