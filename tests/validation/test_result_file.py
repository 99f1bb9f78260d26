"""The result file: its layout (README), units, round trip of the config, flagged partial results, backups."""

import h5py
import numpy as np
import pytest
import yaml

from clearsim.io.hdf5 import NotAResultFile, read_attributes, read_result
from clearsim.model.loader import load_mechanism, load_mechanism_text
from clearsim.runner import contents_serve, prepare, result_file_bytes, run_to_file

from .conftest import CONFIGS

SHORT = ("solver.t_end=3ms",)


def run(tmp_path, name="sc.h5", overrides=SHORT, progress=None):
    loaded = load_mechanism(CONFIGS / "slider_crank_flores.yaml", overrides)
    return run_to_file(prepare(loaded), loaded, tmp_path / name, progress), loaded


def test_a_file_of_the_sensors_alone_holds_the_full_files_sensors_bit_for_bit(tmp_path):
    """contents="sensors" (a diagnosis's model runs): the time, the sensors and the contact episodes, equal to those
    of the full file of the same run, and none of the other histories."""
    full, loaded = run(tmp_path)
    reduced = run_to_file(prepare(loaded), loaded, tmp_path / "sensors.h5", contents="sensors")
    a, b = read_result(full.output), read_result(reduced.output)
    assert b["attrs"]["contents"] == "sensors" and "contents" not in a["attrs"] and bool(b["attrs"]["complete"])
    assert b["time"].shape == (301,) and np.array_equal(a["time"], b["time"])
    sensors = [name for name in a if name.startswith("sensors/")]
    assert sensors and all(np.array_equal(a[name], b[name]) for name in sensors)
    assert {name for name in b if name != "attrs"} == {"time", *sensors} | {name for name in a if "/episodes/" in name}
    assert reduced.output.stat().st_size < 0.3 * full.output.stat().st_size


def test_a_summary_file_holds_every_history_but_the_bodies_and_reactions_bit_for_bit(tmp_path):
    """contents="summary" (`clearsim sweep --keep summary`): the full file's datasets without /bodies/ and the ideal
    joints' /reaction, each equal to the full file's; the clearance joints' histories, energies, drivers, sensors and
    the constraint violation all there; the size estimate that guards the free disk space shrinks to match."""
    full, loaded = run(tmp_path)  # the slider-crank with its clearance joint slider_pin
    system = prepare(loaded)
    reduced = run_to_file(system, loaded, tmp_path / "summary.h5", contents="summary")
    a, b = read_result(full.output), read_result(reduced.output)
    assert b["attrs"]["contents"] == "summary" and bool(b["attrs"]["complete"])
    dropped = {name for name in a if name.startswith("bodies/") or name.endswith("/reaction")}
    assert len(dropped) == 3 * 3 + 3  # q, q̇, q̈ of three bodies; the three ideal joints' reactions
    assert set(b) == set(a) - dropped
    assert {"joints/slider_pin/eccentricity", "joints/slider_pin/normal_force", "energy/kinetic",
            "constraints/violation", "drivers/crank_drive/effort", "sensors/slider_acceleration"} <= set(b)
    assert all(np.array_equal(a[name], b[name]) for name in b if name != "attrs")
    assert reduced.output.stat().st_size < 0.6 * full.output.stat().st_size
    assert result_file_bytes(system, "sensors") < result_file_bytes(system, "summary") < result_file_bytes(system)


def test_which_files_serve_which_contents():
    """Each contents is a subset of the one before: all ⊇ summary ⊇ sensors; an unknown value serves nothing."""
    assert [held for held in ("all", "summary", "sensors") if contents_serve(held, "summary")] == ["all", "summary"]
    assert contents_serve("summary", "sensors") and not contents_serve("sensors", "summary")
    assert not contents_serve("summary", "all") and not contents_serve("bodies", "sensors")


def test_the_attributes_alone_are_those_of_the_whole_read_and_a_cut_file_is_refused(tmp_path):
    """read_attributes (the sweep's reuse check) reads no dataset but gives the same attributes; a file cut short (a
    hard kill, a full disk) is refused as not readable, so the case runs again."""
    report, _ = run(tmp_path)
    assert read_attributes(report.output) == read_result(report.output)["attrs"]
    data = report.output.read_bytes()
    cut = tmp_path / "cut.h5"
    cut.write_bytes(data[:len(data) // 2])
    with pytest.raises(NotAResultFile):
        read_attributes(cut)


def test_layout_units_and_attributes(tmp_path):
    report, _ = run(tmp_path)
    with h5py.File(report.output) as f:
        for key in ("clearsim_version", "created", "config_yaml", "complete", "status", "wall_time_s", "steps",
                    "rhs_evaluations"):
            assert key in f.attrs, key
        assert bool(f.attrs["complete"]) and f.attrs["status"] == "complete"
        samples = f["time"].shape[0]
        assert samples == 301 and f["time"].attrs["unit"] == "s"
        for body in ("crank", "rod", "slider"):
            for kind in ("q", "qd", "qdd"):
                assert f[f"bodies/{body}/{kind}"].shape == (samples, 3)
        for joint in ("crank_pivot", "crank_pin", "slider_guide"):
            assert f[f"joints/{joint}/reaction"].shape == (samples, 2)
        assert f["joints/slider_pin/eccentricity"].shape == (samples, 2)
        for name in ("penetration", "normal_force", "friction_force", "mode"):
            assert f[f"joints/slider_pin/{name}"].shape == (samples,)
        assert f["joints/slider_pin/mode"].dtype == np.int8
        for kind in ("kinetic", "potential", "contact_dissipated", "friction_dissipated", "driver_work"):
            assert f[f"energy/{kind}"].shape == (samples,)
        assert f["constraints/violation"].shape == (samples,)
        assert f["sensors/slider_velocity"].shape == (samples,)
        missing_units = []
        f.visititems(lambda name, node: missing_units.append(name)
                     if isinstance(node, h5py.Dataset) and "unit" not in node.attrs else None)
        assert missing_units == []


def test_config_text_reproduces_the_run(tmp_path):
    report, loaded = run(tmp_path)
    stored = read_result(report.output)["attrs"]["config_yaml"]
    again = load_mechanism_text(stored)
    assert again.mechanism == loaded.mechanism
    assert yaml.safe_load(stored)["solver"]["t_end"] == "3ms"


def test_interrupted_run_leaves_a_readable_flagged_file(tmp_path):
    def interrupt(t):
        if t > 1e-3:
            raise KeyboardInterrupt

    report, _ = run(tmp_path, progress=interrupt)
    result = read_result(report.output)
    assert not result["attrs"]["complete"]
    assert result["attrs"]["status"].startswith("interrupted")
    assert 0.001 <= result["time"][-1] < 0.003
    assert result["bodies/rod/q"].shape[0] == result["time"].shape[0]


def test_solver_failure_keeps_samples_and_names_time_and_joint(tmp_path):
    report, _ = run(tmp_path, overrides=SHORT + ("solver.min_step=2e-5s",))
    assert not report.complete
    message = str(report.error)
    assert "slider_pin" in message and "min_step" in message and "ms" in message
    result = read_result(report.output)
    assert result["attrs"]["status"].startswith("failed")
    assert 0.0 < result["time"][-1] < 0.003  # everything up to the failure is there


def test_an_existing_result_is_kept_as_previous_and_never_overwritten(tmp_path):
    first, _ = run(tmp_path)
    created = read_result(first.output)["attrs"]["created"]
    second, _ = run(tmp_path)
    assert second.backup == tmp_path / "sc.previous.h5"
    assert read_result(second.backup)["attrs"]["created"] == created
    third, _ = run(tmp_path)
    assert third.backup == tmp_path / "sc.previous-2.h5"
    assert read_result(second.backup)["attrs"]["created"] == created  # the older kept result is still there


def test_a_selective_read_and_the_summary_agree_with_the_whole_file(tmp_path):
    """read_result(path, wanted) returns exactly the accepted datasets, equal to a whole read; the summary
    `clearsim run` prints (which reads only what it needs) equals the peaks of the whole file and of its steps."""
    from clearsim.runner import summarize

    report, _ = run(tmp_path)
    whole = read_result(report.output)
    some = read_result(report.output, lambda name: name.startswith("sensors/"))
    assert set(some) == {"attrs"} | {name for name in whole if name.startswith("sensors/")}
    for name in set(some) - {"attrs"}:
        assert np.array_equal(some[name], whole[name])
    assert set(read_result(report.output, lambda name: name in ("bodies", "time"))) == {"attrs", "time"}  # no group
    summary = summarize(report.output)
    assert summarize(report.output, whole) == summary  # from data already read (a sweep's record)
    sampled = float(np.max(np.abs(whole["sensors/slider_acceleration"])))
    at_step_ends = float(whole["attrs"]["peak_output_acceleration"])  # the first impact peaks between samples
    assert summary.peak_acceleration == ("slider_acceleration", max(sampled, at_step_ends)) and at_step_ends > sampled
    mode = whole["joints/slider_pin/mode"]
    assert summary.contact_time_share["slider_pin"] == tuple(float(np.mean(mode == m)) for m in (0, 1, 2))
    assert summary.peak_contact_force["slider_pin"] >= float(np.max(whole["joints/slider_pin/normal_force"]))


def stored_bytes_per_sample(path) -> float:
    """Uncompressed bytes per sample of every per-sample dataset of a result file (the episode tables excluded)."""
    with h5py.File(path, "r") as handle:
        samples = len(handle["time"])
        sizes = []
        handle.visititems(lambda name, node: sizes.append(node.size * node.dtype.itemsize)
                          if isinstance(node, h5py.Dataset) and node.shape[:1] == (samples,)
                          and "/episodes/" not in name else None)
    return sum(sizes) / samples


SIZE_CASES = {  # name: (configuration, overrides)
    "hydraulic breaker": (CONFIGS / "uhv_breaker_hydraulic.yaml", ("solver.t_end=5ms",)),
    "lubricated slider-crank": (CONFIGS / "slider_crank_flores.yaml",
                                SHORT + ("joints.slider_pin.lubrication.viscosity=1e-4 Pa*s",
                                         "joints.slider_pin.lubrication.length=10 mm")),
    "breaker wearing at J": (CONFIGS / "uhv_breaker.yaml",
                             ("solver.t_end=5ms", "joints.J.wear={archard: {coefficient: 1e-4, hardness: 2 GPa, "
                              "length: 40 mm}}")),
}


@pytest.mark.parametrize("case", list(SIZE_CASES))
def test_the_size_estimate_counts_every_dataset_the_run_writes(tmp_path, case):
    """The free-space guard's estimate counts each per-sample value of the file: the hydraulic breaker's /drives and
    /energy entries of its cylinder, gas load and guide friction, a lubricated joint's film datasets. Per sample it
    lies between the real file's uncompressed bytes and 5 % above them (int8 datasets are counted as 4 bytes); the
    whole estimate (whole 1024-row chunks, 20 % over, 1 MiB for attributes and tables) covers the file (hydraulic
    breaker, 5 ms: 1.99 MB estimated, 0.58 MB written, most of the difference the 1 MiB and the chunk's 523 empty rows)."""
    from clearsim.runner import result_sample_bytes

    config, overrides = SIZE_CASES[case]
    loaded = load_mechanism(config, overrides)
    system = prepare(loaded)
    report = run_to_file(system, loaded, tmp_path / "run.h5")
    assert report.complete, report.status
    written = stored_bytes_per_sample(report.output)
    assert written <= result_sample_bytes(system) <= 1.05 * written
    assert report.output.stat().st_size <= result_file_bytes(system)
