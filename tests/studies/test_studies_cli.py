"""`fi-design sweep`, `study` and `robustness` through typer's CliRunner."""

from __future__ import annotations

import csv
import json
import re
import shutil
from types import SimpleNamespace

import pytest
from typer.testing import CliRunner

from fi_design.cli.app import app

runner = CliRunner()


def run(*args: str):
    return runner.invoke(app, [str(a) for a in args], catch_exceptions=False)


# ----------------------------------------------------------------- runs the tests read (once)


@pytest.fixture(scope="module")
def sweep_run(paper_spec_path, tmp_path_factory):
    """`sweep` of crossover x stroke (3 x 2 points) with its CSV, JSON and figure."""
    d = tmp_path_factory.mktemp("sweep")
    out = SimpleNamespace(csv=d / "m.csv", json=d / "m.json", figure=d / "m.svg")
    r = run("sweep", paper_spec_path, "--x", "controller.crossover=3 Hz:9 Hz:3",
            "--y", "isolator.stroke=0.1 mm:0.3 mm:2", "--csv", out.csv, "--json", out.json,
            "--figure", out.figure, "--jobs", "1")
    assert r.exit_code == 0, r.output
    out.output = r.output
    return out


@pytest.fixture(scope="module")
def study_dir(paper_spec_path, tmp_path_factory):
    """`study paper` at 2 points per axis, all four maps: the directory and the console."""
    out = tmp_path_factory.mktemp("study") / "study"
    r = run("study", "paper", paper_spec_path, "--out", out, "--resolution", "2", "--jobs", "1")
    assert r.exit_code == 0, r.output
    return SimpleNamespace(path=out, output=r.output)


#: The robustness run the tests read: 4 samples, friction and its variation along the rail.
ROBUSTNESS_ARGS = ("--samples", "4", "--scatter", "friction.static=10%", "--scatter",
                   "friction.coulomb=0.1 N", "--seed", "7", "--position-friction", "10%:20 mm",
                   "--jobs", "1")


@pytest.fixture(scope="module")
def robustness_run(paper_spec_path, tmp_path_factory):
    """`robustness` (default measure: the stage) with its CSV and JSON."""
    d = tmp_path_factory.mktemp("robustness")
    out = SimpleNamespace(csv=d / "r.csv", json=d / "r.json")
    r = run("robustness", paper_spec_path, *ROBUSTNESS_ARGS, "--csv", out.csv,
            "--json", out.json)
    assert r.exit_code == 0, r.output
    out.output = r.output
    return out


#: Columns without a unit: counts and text (in a robustness CSV after the plant's prefix).
UNITLESS = {"sample", "hunting_cycles", "verdict", "status", "message"}


def column_units(path) -> dict:
    """The unit each column of a CSV file names after its last underscore (``time_s``,
    ``controller.crossover_Hz``); None for the columns that have none."""
    from fi_design.spec.units import KNOWN_UNITS

    header = next(csv.reader(path.open()))
    units = {}
    for name in header:
        if re.sub(r"^(not_)?isolated_", "", name) in UNITLESS:
            units[name] = None
            continue
        head, _, unit = name.rpartition("_")
        assert head and unit in KNOWN_UNITS and unit != "1", \
            f"{path.name}: column {name!r} names no unit"
        units[name] = unit
    return units


def test_every_csv_column_names_its_unit(sweep_run, study_dir, robustness_run):
    """The studies' CSV files named their columns by the bare quantity (`amplitude`,
    `controller.crossover`, `phase`): a reader could not tell metres from millimetres, hertz
    from rad/s. Every column now carries its unit as the measured-data layout does
    (`amplitude_m`), the swept and scattered values theirs from the spec (the JSON's axis
    units), or is a count or text."""
    units = column_units(sweep_run.csv)
    axes = json.loads(sweep_run.json.read_text())
    assert units == {f"controller.crossover_{axes['x']['unit']}": "Hz",
                     f"isolator.stroke_{axes['y']['unit']}": "m", "hunting_cycles": None,
                     "amplitude_m": "m", "period_s": "s", "verdict": None, "status": None,
                     "message": None}
    study = json.loads((study_dir.path / "study.json").read_text())
    for m in study["maps"]:
        units = column_units(study_dir.path / f"map_{m['definition']['key']}.csv")
        x, y = m["result"]["x"], m["result"]["y"]
        assert list(units)[:2] == [f"{x['path']}_{x['unit']}", f"{y['path']}_{y['unit']}"]
        assert list(units)[2:] == ["hunting_cycles", "amplitude_m", "period_s", "verdict",
                                   "status", "message"]
    units = column_units(robustness_run.csv)
    assert list(units)[:4] == ["sample", "friction.static_N", "friction.coulomb_N", "phase_rad"]
    for plant in ("isolated", "not_isolated"):
        assert units[f"{plant}_amplitude_m"] == "m" and units[f"{plant}_period_s"] == "s"
    # the values are in the unit the header names (SI)
    row = next(csv.DictReader(sweep_run.csv.open()))
    assert float(row["isolator.stroke_m"]) == pytest.approx(1e-4)
    assert float(row["controller.crossover_Hz"]) == pytest.approx(3.0)


def test_robustness_csv_carries_what_the_stage_measure_gives(robustness_run):
    """Under the default measure (the stage over its moves) a sample's cycles are not
    counted, and the CSV's only outcome column per plant besides the verdict,
    hunting_cycles, was empty: no amplitude at all. It now carries what the JSON's points
    hold: the peak to peak of the cycle the hunting move ends in [m], its period [s], and the
    message naming that move."""
    data = json.loads(robustness_run.json.read_text())
    assert data["measure"] == "stage"
    points = {(p["isolated"], p["index"][0]): p for p in data["points"]}
    rows = list(csv.DictReader(robustness_run.csv.open()))
    assert len(rows) == data["samples"] == 4
    hunted = 0
    for plant, iso in (("isolated", True), ("not_isolated", False)):
        for n, row in enumerate(rows):
            p = points[(iso, n)]
            assert row[f"{plant}_verdict"] == p["verdict"] and row[f"{plant}_hunting_cycles"] == ""
            assert row[f"{plant}_message"] == p["message"]
            if p["verdict"] != "hunting":
                assert row[f"{plant}_amplitude_m"] in ("", "0.0")
                continue
            hunted += 1
            amp, period = float(row[f"{plant}_amplitude_m"]), float(row[f"{plant}_period_s"])
            assert amp == pytest.approx(p["amplitude"]) and period == pytest.approx(p["period"])
            # the message names the move that hunts and its cycle, to 3 digits
            said = re.search(r"move hunts.*: ([\d.]+) (mm|µm) peak to peak, period ([\d.]+) s",
                             row[f"{plant}_message"])
            assert said, row[f"{plant}_message"]
            scale = {"mm": 1e-3, "µm": 1e-6}[said.group(2)]
            assert amp == pytest.approx(float(said.group(1)) * scale, rel=6e-3)
            assert period == pytest.approx(float(said.group(3)), rel=6e-3)
    assert hunted  # the scattered stage hunts in some samples: the columns are exercised


# --------------------------------------------------------------------------- sweep


def test_sweep_writes_csv_json_and_figure(paper_spec_path, sweep_run):
    out_csv, out_json, fig, output = sweep_run.csv, sweep_run.json, sweep_run.figure, \
        sweep_run.output
    assert "points:" in output and "peak to peak of the cycle some move ends in" in output
    one = run("sweep", paper_spec_path, "--x", "controller.crossover=3 Hz:9 Hz:3",
              "--measure", "move", "--jobs", "1")
    assert one.exit_code == 0 and "hunting cycles of the spec's move in the window" in one.output
    bad = runner.invoke(app, ["sweep", str(paper_spec_path), "--x", "controller.crossover=3:9:2",
                              "--measure", "moves"])
    assert bad.exit_code == 2 and "--measure" in bad.output
    rows = list(csv.DictReader(out_csv.open()))
    assert list(rows[0])[:6] == ["controller.crossover_Hz", "isolator.stroke_m",
                                 "hunting_cycles", "amplitude_m", "period_s", "verdict"]
    assert len(rows) == 6 and float(rows[0]["isolator.stroke_m"]) == pytest.approx(1e-4)
    data = json.loads(out_json.read_text())
    assert data["x"]["unit"] == "Hz" and data["y"]["values"][1] == pytest.approx(3e-4)
    assert fig.read_bytes().startswith(b"<?xml")


def test_sweep_default_executor_and_cache(paper_spec_path, tmp_path, monkeypatch):
    monkeypatch.setenv("FI_DESIGN_CACHE_DIR", str(tmp_path / "cache"))
    args = ("sweep", paper_spec_path, "--x", "controller.crossover=2:20:4", "--no-isolator")
    first = run(*args)
    assert first.exit_code == 0, first.output
    assert "4 evaluated now, 0 from the cache" in first.output and "worker processes" in first.output
    second = run(*args)
    assert "0 evaluated now, 4 from the cache" in second.output
    third = run(*args, "--no-cache", "--jobs", "1")
    assert "4 evaluated now" in third.output and "serial" in third.output


def test_sweep_one_dimensional_with_invalid_points(paper_spec_path, tmp_path):
    out = tmp_path / "line.csv"
    r = run("sweep", paper_spec_path, "--x", "friction.static=0.5 N:4 N:2", "--no-isolator",
            "--csv", out, "--jobs", "1")
    assert r.exit_code == 0, r.output
    rows = list(csv.DictReader(out.open()))
    assert rows[0]["verdict"] == "invalid" and "Coulomb" in rows[0]["message"]
    assert rows[1]["verdict"] == "hunting"


def _drawn_guide_spec(paper_spec_path, tmp_path):
    """The paper setup with its guide drawn (60 x 15 mm leaves, standing) defining the joint."""
    import yaml

    d = yaml.safe_load(paper_spec_path.read_text())
    iso = d["isolator"]
    for key in ("stiffness", "damping", "parasitic_modes"):
        iso.pop(key)
    iso["flexure"].update(length="60 mm", width="15 mm", thickness="0.4 mm")
    path = tmp_path / "drawn.yaml"
    path.write_text(yaml.safe_dump(d, sort_keys=False))
    return path


def test_sweep_marks_points_whose_guide_buckles(paper_spec_path, tmp_path):
    """Leaves of 0.1 mm buckle under the 1.6 kg stage (net drive stiffness about -205 N/m):
    such a point is `buckled`, not simulated, in the CSV, the console and the map; the
    0.4 mm leaves (+1463 N/m) are simulated as before."""
    spec = _drawn_guide_spec(paper_spec_path, tmp_path)
    out, fig = tmp_path / "line.csv", tmp_path / "line.svg"
    r = run("sweep", spec, "--x", "isolator.flexure.thickness=0.1 mm,0.4 mm", "--measure",
            "move", "--csv", out, "--figure", fig, "--jobs", "1", "--no-cache")
    assert r.exit_code == 0, r.output
    rows = list(csv.DictReader(out.open()))
    assert rows[0]["verdict"] == "buckled" and rows[0]["status"] == "invalid"
    assert "buckled the guide" in rows[0]["message"] and rows[0]["amplitude_m"] == ""
    assert rows[1]["verdict"] != "buckled" and rows[1]["status"] == "ok"
    said = " ".join(r.output.split())  # the console folds lines at its width
    assert "1 buckled" in said and "b the weight has buckled the guide" in said
    assert "guide buckled by the weight" in fig.read_text()


def test_buckled_cells_have_their_own_colour_and_legend_entry(repo_root):
    """A map's buckled cell is filled in its own colour, with a legend entry."""
    import matplotlib
    import numpy as np

    from fi_design import plots
    from fi_design.results.studies import SweepResult
    from fi_design.spec.file import load_spec
    from fi_design.studies.axes import make_axis
    from fi_design.studies.points import grid, point_result, verdict_grid

    spec = load_spec(repo_root / "examples" / "paper_setup.yaml")
    x = make_axis("controller.crossover", [4.0, 8.0], spec=spec)
    y = make_axis("isolator.stroke", [1e-4, 3e-4], spec=spec)
    outs = [dict(status="invalid", verdict="buckled", message="buckled"),
            dict(status="ok", verdict="hunting", amplitude=1e-3),
            dict(status="ok", verdict="settled", amplitude=0.0),
            dict(status="invalid", verdict="invalid", message="no")]
    pts = [point_result(idx, v, True, o) for idx, v, o in
           zip([(0, 0), (0, 1), (1, 0), (1, 1)], [(4.0, 1e-4), (8.0, 1e-4), (4.0, 3e-4),
                                                  (8.0, 3e-4)], outs)]
    res = SweepResult(spec=spec, x=x, y=y, isolated=True, points=tuple(pts),
                      hunting_cycles=grid(pts, (2, 2), "hunting_cycles"),
                      amplitude=grid(pts, (2, 2), "amplitude"),
                      period=grid(pts, (2, 2), "period"), verdict=verdict_grid(pts, (2, 2)),
                      design_point=(8.0, 3e-4), run=None, measure="stage")
    fig = plots.sweep_figure(res)
    ax = fig.axes[0]
    legend = ax.get_legend()
    assert legend is not None
    labels = [t.get_text() for t in legend.get_texts()]
    assert plots.studies.BUCKLED_LABEL in labels and "design point" in labels
    colours = {matplotlib.colors.to_hex(p.get_facecolor()) for p in ax.patches}
    assert plots.studies.BUCKLED_COLOUR in colours
    assert res.counts()["buckled"] == 1 and np.isnan(res.boundary("above")[0])


@pytest.mark.parametrize("args,words", [
    (["--x", "isolator.strok=1 mm:2 mm:3"], "did you mean 'stroke'"),
    (["--x", "isolator.stroke=1 mm:2 mm"], "START:STOP:N"),
    (["--x", "isolator.stroke=1 N:2 N:3"], "not a length"),
    (["--x", "isolator.stroke=1 mm:2 mm:0"], "at least 1"),
    (["--x", "isolator.stroke=0.2:1 mm:3"], "'0.2' is a bare number"),
    (["--x", "motion.moves[5].distance=1 mm,2 mm"], "index 5 is out of range"),
    (["--x", "isolator.stroke=1 mm:2 mm:2", "--log", "z"], "expected x or y"),
    (["--x", "isolator.stroke=1 mm:2 mm:2", "--executor", "spark"], "local, dask"),
    (["--x", "isolator.stroke=1 mm:2 mm:2", "--scheduler", "tcp://x:1"], "--executor dask"),
])
def test_sweep_bad_input_exits_2(paper_spec_path, tmp_path, args, words):
    out = tmp_path / "never.csv"
    r = runner.invoke(app, ["sweep", str(paper_spec_path), *args, "--csv", str(out), "--jobs",
                            "1"])
    assert r.exit_code == 2, r.output
    assert words in r.output
    assert not out.exists()


def test_existing_output_refused_before_any_work(paper_spec_path, tmp_path):
    csv_out, json_out = tmp_path / "m.csv", tmp_path / "m.json"
    csv_out.write_text("keep me")
    r = runner.invoke(app, ["sweep", str(paper_spec_path), "--x", "controller.crossover=3:9:2",
                            "--json", str(json_out), "--csv", str(csv_out)])
    assert r.exit_code == 2 and "file exists; use --force" in r.output
    assert csv_out.read_text() == "keep me" and not json_out.exists()
    r = run("sweep", paper_spec_path, "--x", "controller.crossover=3:9:2", "--csv", csv_out,
            "--force", "--jobs", "1")
    assert r.exit_code == 0 and csv_out.read_text().startswith("controller.crossover_Hz,")


def test_study_paper(paper_spec_path, study_dir):
    out = study_dir.path
    for name in ("figure4.svg", "figure4.png", "study.json", "map_A.csv", "map_B.csv",
                 "map_C.csv", "map_D.csv"):
        assert (out / name).is_file(), name
    data = json.loads((out / "study.json").read_text())
    assert [m["definition"]["key"] for m in data["maps"]] == ["A", "B", "C", "D"]
    assert "D) crossover vs stroke, with isolator" in study_dir.output
    again = runner.invoke(app, ["study", "paper", str(paper_spec_path), "--out", str(out),
                                "--resolution", "2", "--jobs", "1"])
    assert again.exit_code == 2 and "file exists" in again.output


def test_study_force_leaves_no_map_of_an_earlier_study(paper_spec_path, study_dir, tmp_path,
                                                       monkeypatch):
    """`study paper --maps A --force` into the directory of an earlier study of all four
    maps left map_B.csv ... map_D.csv beside a study.json of map A only. Without --force
    such a file is refused before any work; with it the stale maps go, and no other file.
    (The map's points come from the cache of the earlier study; the figure, which this test
    does not read, is not drawn.)"""
    from fi_design import plots

    monkeypatch.setattr(plots, "study_figure", lambda result: None)
    monkeypatch.setattr(plots, "figure_bytes", lambda fig, fmt: b"figure")
    out = tmp_path / "study"
    shutil.copytree(study_dir.path, out)
    (out / "notes.txt").write_text("mine")
    (out / "map_E.csv").write_text("mine too")  # not a map of the study
    for name in ("figure4.svg", "figure4.png", "study.json", "map_A.csv"):
        (out / name).unlink()  # nothing this run writes is there: only the other maps
    refused = runner.invoke(app, ["study", "paper", str(paper_spec_path), "--out", str(out),
                                  "--maps", "A", "--resolution", "2", "--jobs", "1"])
    assert refused.exit_code == 2 and "map_B.csv" in refused.output \
        and "--force" in refused.output, refused.output
    assert not (out / "study.json").exists() and (out / "map_B.csv").is_file()
    shutil.copy(study_dir.path / "study.json", out / "study.json")
    r = run("study", "paper", paper_spec_path, "--out", out, "--maps", "A", "--resolution", "2",
            "--jobs", "1", "--force")
    assert r.exit_code == 0, r.output
    assert sorted(p.name for p in out.iterdir()) == ["figure4.png", "figure4.svg", "map_A.csv",
                                                     "map_E.csv", "notes.txt", "study.json"]
    assert "removed map_B.csv, map_C.csv, map_D.csv" in " ".join(r.output.split())
    data = json.loads((out / "study.json").read_text())
    assert [m["definition"]["key"] for m in data["maps"]] == ["A"]
    assert (out / "notes.txt").read_text() == "mine"


def test_study_errors(paper_spec_path, repo_root, tmp_path):
    r = runner.invoke(app, ["study", "papr", str(paper_spec_path), "--out", str(tmp_path / "s")])
    assert r.exit_code == 2 and "did you mean 'paper'" in r.output
    r = runner.invoke(app, ["study", "paper", str(repo_root / "examples" / "no_isolator.yaml"),
                            "--out", str(tmp_path / "s"), "--jobs", "1"])
    assert r.exit_code == 2 and "isolator" in r.output and not (tmp_path / "s").exists()


def test_robustness_reproducible_with_seed(paper_spec_path, robustness_run, tmp_path):
    out = tmp_path / "r1.json"
    r = run("robustness", paper_spec_path, *ROBUSTNESS_ARGS, "--json", out, "--no-cache")
    assert r.exit_code == 0, r.output
    assert "Probability of hunting" in r.output and "Probability of hunting" in \
        robustness_run.output
    a, b = json.loads(robustness_run.json.read_text()), json.loads(out.read_text())
    assert a["draws"] == b["draws"] and a["points"] == b["points"]
    assert a["isolated"]["probability"] == b["isolated"]["probability"]
    assert a["scatter"] == b["scatter"]


def test_robustness_json_names_the_unit_of_every_scatter(robustness_run):
    """The robustness JSON's `scatter` entries gave an absolute spread (`friction.coulomb=0.1
    N`: `"spread": 0.1`) without a unit, and nothing in the JSON named the unit of the drawn
    values its `draws` hold, which the CSV names (`friction.static_N`). Each entry now names
    the unit of its value, its column's in the CSV, and the unit of its spread (1 for a
    fraction of the nominal value); the console prints each spread with its unit."""
    data = json.loads(robustness_run.json.read_text())
    scatter = {s["path"]: s for s in data["scatter"]}
    assert scatter["friction.coulomb"] == {"path": "friction.coulomb", "spread": 0.1,
                                           "relative": False, "meaning": "", "unit": "N",
                                           "spread_unit": "N"}
    assert scatter["friction.static"]["spread_unit"] == "1"
    assert scatter["friction.static"]["spread"] == pytest.approx(0.1)
    # the value's unit is the one the CSV's column names
    columns = list(column_units(robustness_run.csv))[1:1 + len(data["scatter"])]
    assert columns == [f"{s['path']}_{s['unit']}" for s in data["scatter"]]
    lines = [ln.strip() for ln in robustness_run.output.splitlines()]
    assert "scatter friction.coulomb: normal, spread 0.1 N" in lines
    assert "scatter friction.static: normal, spread 0.1 of nominal (10 %)" in lines


@pytest.mark.parametrize("args,words", [
    ([], "--scatter"),
    (["--scatter", "friction.statik=10%"], "did you mean 'static'"),
    (["--scatter", "friction.static=10"], "fraction"),
    (["--scatter", "friction.static=10%", "--distribution", "cauchy"], "normal or uniform"),
    (["--scatter", "friction.static=10%", "--position-friction", "10%"], "AMPLITUDE:WAVELENGTH"),
])
def test_robustness_bad_input_exits_2(paper_spec_path, tmp_path, args, words):
    out = tmp_path / "never.json"
    r = runner.invoke(app, ["robustness", str(paper_spec_path), "--samples", "2", *args,
                            "--json", str(out), "--jobs", "1"])
    assert r.exit_code == 2, r.output
    assert words in r.output
    assert not out.exists()


@pytest.mark.slow
def test_sweep_on_local_dask_cluster(paper_spec_path, tmp_path):
    out = tmp_path / "d.csv"
    r = run("sweep", paper_spec_path, "--x", "controller.crossover=3:9:3", "--executor", "dask",
            "--jobs", "2", "--csv", out, "--no-cache")
    assert r.exit_code == 0, r.output
    assert "local dask cluster" in r.output and len(out.read_text().splitlines()) == 4
