"""campaign.runner on a local Ray with 2 workers: the same numbers for 1 and 2 workers in
flight, an interrupted campaign resumes to the same numbers, a cut last line is dropped;
``radar curves`` refuses bad input in one line with exit status 2 before starting Ray."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from campaign.runner import CampaignError, Task, merge, read_results, run, split
from radar.cli import main

SHAPE = [32, 64]


def tiny_tasks() -> list[Task]:
    """A few seconds of real work: detection maps (noise only and with targets), the
    estimators and the resolution test."""
    return (split("detection", {"swerling": 1, "cell_snr_db": 3.0, "pfas": [1e-2, 1e-4],
                                "shape": SHAPE}, 3, 1)
            + split("detection", {"swerling": 0, "cell_snr_db": None, "pfas": [1e-2, 1e-4],
                                  "shape": SHAPE}, 2, 1)
            + split("estimation", {"snr_db": -40.0, "azimuth_deg": 10.0,
                                   "chains": ["float", "quantised"]}, 40, 20)
            + split("resolution", {"sep_bw": 0.8, "cell_snr_db": 20.0}, 40, 20))


@pytest.fixture(scope="module")
def local_ray():
    """One local Ray with 2 CPUs for the module (start-up included in the tests' time)."""
    ray = pytest.importorskip("ray")
    from campaign.runner import RaySession
    session = RaySession(workers=2)
    session.open()
    yield ray
    session.close()


def test_same_numbers_for_one_and_two_workers(local_ray, tmp_path: Path) -> None:
    tasks = tiny_tasks()
    one = run(tasks, 5, tmp_path / "one.jsonl", workers=1)
    two = run(tasks, 5, tmp_path / "two.jsonl", workers=2)
    assert one == two
    assert merge(one[t.key(5)] for t in tasks[:3])["cells"] > 0
    other_seed = run(tasks[:1], 6, tmp_path / "one.jsonl", workers=2)
    assert other_seed != {tasks[0].key(5): one[tasks[0].key(5)]}


def test_interrupted_campaign_resumes_to_the_same_numbers(local_ray, tmp_path: Path) -> None:
    tasks = tiny_tasks()
    full = run(tasks, 9, tmp_path / "full.jsonl", workers=2)
    part = tmp_path / "part.jsonl"
    seen = []

    def stop(task: Task, result: dict) -> None:
        seen.append(task)
        if len(seen) == 3:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run(tasks, 9, part, workers=2, on_result=stop)
    assert len(read_results(part)) == 3
    with open(part, "a") as f:           # a kill in the middle of a line
        f.write('{"key": "abc", "res')
    again = run(tasks, 9, part, workers=2)
    assert again == full
    lines = part.read_text().splitlines()
    assert len(lines) == len(tasks) and all(json.loads(line) for line in lines)


def test_task_seeds_do_not_depend_on_the_split() -> None:
    """A trial's numbers depend on its index, not on the task that holds it."""
    from campaign.runner import execute
    params = {"snr_db": -40.0, "azimuth_deg": 10.0, "chains": ["float", "quantised"]}
    whole = split("estimation", params, 6, 6)[0]
    parts = split("estimation", params, 6, 2)
    a = execute(whole.kind, params, 0, 6, 3, whole.group())
    b = merge(execute(t.kind, params, t.first, t.count, 3, t.group()) for t in parts)
    assert a == pytest.approx(b, rel=1e-12)


def test_bad_campaign_inputs() -> None:
    with pytest.raises(CampaignError, match="trials"):
        split("estimation", {}, 0, 10)
    with pytest.raises(CampaignError, match="workers"):
        run([], 1, Path("unused.jsonl"), workers=0)


@pytest.mark.parametrize("argv", [
    ["--trials", "0"],
    ["--pfa", "1.5"],
    ["--pfa", "0"],
    ["--cell-snr", "50", "60", "1"],
    ["--snr", "nan", "0", "1"],
    ["--snr", "-10", "-20", "1"],
    ["--workers", "0"],
    ["--frame-trials", "-1"],
    ["--seed", "-1"],
    ["--ray-address", "127.0.0.1:1"],
    ["--ray-address", "nonsense"],
])
def test_curves_bad_input_one_line_exit_2(tmp_path: Path, capsys, argv: list[str]) -> None:
    assert main(["curves", "--json", str(tmp_path / "c.json"), *argv]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("radar curves: error: "), err
    assert not (tmp_path / "c.json").exists()


def test_curves_unreachable_ray_address_from_the_environment(tmp_path: Path, capsys,
                                                            monkeypatch) -> None:
    monkeypatch.setenv("RAY_ADDRESS", "127.0.0.1:1")
    assert main(["curves", "--quick", "--json", str(tmp_path / "c.json")]) == 2
    assert "no Ray cluster at 127.0.0.1:1" in capsys.readouterr().err


def test_radar_curves_tiny_run_and_resume(local_ray, tmp_path: Path) -> None:
    """The whole command on tiny grids: the JSON layout of docs/curves.md, theory at SNR 0
    equal to the Pfa, a second run served from the results file."""
    out = tmp_path / "curves.json"
    argv = ["curves", "--quick", "--json", str(out), "--trials", "70", "--pfa-cells", "8192",
            "--pfa", "1e-3", "--cell-snr", "-2", "2", "4", "--snr", "-40", "-30", "10",
            "--workers", "2", "--plots", str(tmp_path / "img"), "--frame-trials", "0"]
    assert main(argv) == 0
    doc = json.loads(out.read_text())
    assert len(doc["detection"]) == 5 * 2           # 5 detectors x 2 Swerling cases
    row = doc["detection"][0]
    for key in ("detector", "path", "swerling", "pfa", "train_cells", "guard_cells",
                "effective_train_cells", "integrated_channels", "snr_db", "cell_snr_db",
                "pd", "pd_theory", "trials", "pfa_measured", "pfa_conditional", "snr_at_pd"):
        assert key in row, key
    assert row["train_cells"] == 248 and row["integrated_channels"] == 64
    assert row["snr_db"][0] == pytest.approx(-2 - doc["cell_gain_db"])
    assert {(r["quantity"], r["chain"]) for r in doc["estimation"]} == {
        (q, c) for q in ("range", "radial_velocity", "azimuth") for c in ("float", "quantised")}
    assert sorted(p.name for p in (tmp_path / "img").iterdir())[:2] == [
        "crb_azimuth.png", "crb_radial_velocity.png"]
    lines = (tmp_path / "curves.campaign.jsonl").read_text().count("\n")
    out.unlink()
    assert main(argv) == 0 and json.loads(out.read_text()) == doc
    assert (tmp_path / "curves.campaign.jsonl").read_text().count("\n") == lines
