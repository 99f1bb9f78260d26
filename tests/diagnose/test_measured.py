"""read_measured: CSV and HDF5 records to SI, column mapping, and every bad-data case's message."""

import h5py
import numpy as np
import pytest

from clearsim.diagnose import MeasuredDataError, read_measured
from clearsim.diagnose.measured import parse_mapping
from clearsim.errors import ClearsimError

UNITS = {"slider_displacement": "m", "slider_velocity": "m/s", "crank_angle": "rad"}


def write_csv(path, header, rows):
    path.write_text("# bench 3, run 12\n" + header + "\n" + "".join(",".join(map(str, r)) + "\n" for r in rows))
    return path


def ramp(n=30, *more):
    """Rows of time 0.1·k, a sensor 2·k, and further columns that start at the values given and rise by 0.01 a row."""
    return [(0.1 * k, 2.0 * k, *(m + 0.01 * k for m in more)) for k in range(n)]


def test_csv_units_in_the_header_become_si(tmp_path):
    path = write_csv(tmp_path / "b.csv", "time [ms],slider_displacement [mm],crank_angle [deg]", ramp(30, 1.5))
    data = read_measured(path, UNITS)
    assert data.time[1] == pytest.approx(1e-4)  # 0.1 ms
    assert data.values["slider_displacement"][1] == pytest.approx(2e-3)  # 2 mm
    assert data.values["crank_angle"][0] == pytest.approx(np.radians(1.5))
    assert data.units == {"time": "ms", "slider_displacement": "mm", "crank_angle": "deg"}
    assert data.path == path


def test_mapping_units_by_option_and_extra_columns(tmp_path):
    path = write_csv(tmp_path / "b.csv", "Zeit,Weg,coil_current [A]", ramp(30, 0.2))
    data = read_measured(path, UNITS, mapping=parse_mapping(["Zeit=time,Weg=slider_displacement"]),
                         units={"Zeit": "ms", "Weg": "mm"})
    assert data.values["slider_displacement"][1] == pytest.approx(2e-3)
    assert data.columns == {"slider_displacement": "Weg"} and data.ignored == ["coil_current"]


def test_column_without_unit_is_si(tmp_path):
    data = read_measured(write_csv(tmp_path / "b.csv", "time,slider_displacement", ramp()), UNITS)
    assert data.time[1] == pytest.approx(0.1) and data.values["slider_displacement"][1] == pytest.approx(2.0)


def test_clearsim_result_file_and_plain_hdf5(tmp_path):
    result = tmp_path / "run.h5"
    with h5py.File(result, "w") as f:
        f.attrs["clearsim_version"] = "0"
        f.create_dataset("time", data=np.linspace(0, 1e-3, 30)).attrs["unit"] = "s"
        f.create_dataset("sensors/slider_displacement", data=np.arange(30.0)).attrs["unit"] = "m"
    assert read_measured(result, UNITS).values["slider_displacement"][3] == 3.0
    plain = tmp_path / "bench.hdf5"
    with h5py.File(plain, "w") as f:
        f.create_dataset("time", data=np.arange(30.0)).attrs["unit"] = "ms"
        f.create_dataset("slider_velocity", data=np.arange(30.0))
    data = read_measured(plain, UNITS)
    assert data.time[2] == pytest.approx(2e-3) and set(data.values) == {"slider_velocity"}


BAD = [
    ("missing column", "time [ms],slider_velocity [m/s]", ramp(),
     {"required": ["slider_displacement"]},
     "b.csv: missing column for sensor 'slider_displacement' (columns: time, slider_velocity); "
     "add it, or map a column to it: --map <column>=slider_displacement"),
    ("mapped column absent", "time [ms],slider_displacement [mm]", ramp(), {"mapping": {"Weg": "slider_displacement"}},
     "b.csv: missing column 'Weg' (columns: time, slider_displacement)"),
    ("typo in a column", "time [ms],slider_displacment [mm]", ramp(), {},
     "b.csv: no column names a model sensor ('slider_displacment'; did you mean 'slider_displacement'?)"),
    ("no time column", "t [ms],slider_displacement [mm]", ramp(), {},
     "b.csv: no time column (columns: t, slider_displacement); name it 'time [unit]' or map it: --map <column>=time"),
    ("non-monotonic time", "time [ms],slider_displacement [mm]", [(0.1 * k if k != 7 else 0.3, k) for k in range(30)], {},
     "b.csv:10: time in column 'time' does not increase (0.6 then 0.3); sort the rows by time and remove repeated samples"),
    ("NaN", "time [ms],slider_displacement [mm]", [(k, "nan" if k == 9 else k) for k in range(30)], {},
     "b.csv:12: column 'slider_displacement' is not a finite number (1 such value(s)); "
     "remove those rows or fill the gap before using the record"),
    ("empty cell", "time [ms],slider_displacement [mm]", [(k, "" if k == 4 else k) for k in range(30)], {},
     "b.csv:7: column 'slider_displacement': '' is not a number"),
    ("wrong unit", "time [ms],slider_displacement [deg]", ramp(), {},
     "b.csv: column 'slider_displacement': unit [deg] does not fit (expected a length"),
    ("unknown unit", "time [ms],slider_displacement [furlongz]", ramp(), {},
     "b.csv: column 'slider_displacement': unit [furlongz] does not fit (unknown unit"),
    ("time not a time", "time [mm],slider_displacement [mm]", ramp(), {},
     "b.csv: column 'time': unit [mm] does not fit (expected a time"),
    ("too short", "time [ms],slider_displacement [mm]", ramp(19), {},
     "b.csv: only 19 samples; at least 20 are needed (record longer or sample faster)"),
    ("ragged row", "time [ms],slider_displacement [mm]", [(k, k, 0) if k == 3 else (k, k) for k in range(30)], {},
     "b.csv:6: 3 values for 2 columns (time, slider_displacement); every row needs one value per column"),
    ("unit twice", "time [ms],slider_displacement [mm]", ramp(), {"units": {"slider_displacement": "m"}},
     "b.csv: column 'slider_displacement' is in [mm] by its header but in [m] by the option; give the unit in one place only"),
    ("map to no sensor", "time [ms],Weg [mm]", ramp(), {"mapping": {"Weg": "rod_displacement"}},
     "b.csv: --map Weg=rod_displacement: the model has no sensor 'rod_displacement'"),
    ("two columns of one name", "time [ms],slider_displacement [mm],slider_displacement [m]", ramp(30, 0.5), {},
     "b.csv:2: columns 2 and 3 are both named 'slider_displacement'; which one is meant is ambiguous: "
     "rename or remove one of them"),
    ("a column and a mapped one", "time [ms],slider_displacement [mm],Weg [mm]", ramp(30, 0.5),
     {"mapping": {"Weg": "slider_displacement"}},
     "b.csv: columns 'slider_displacement' (by its name) and 'Weg' (--map Weg=slider_displacement) both give sensor "
     "'slider_displacement'; which one is meant is ambiguous: remove or rename one of them, or map it to another "
     "sensor with --map"),
    ("two time columns", "time [ms],Zeit [s],slider_displacement [mm]", [(0.1 * k, 1e-4 * k, k) for k in range(30)],
     {"mapping": {"Zeit": "time"}},
     "b.csv: columns 'time' (by its name) and 'Zeit' (--map Zeit=time) both give the time; which one is meant is ambiguous"),
    ("dead channel, constant", "time [ms],slider_displacement [mm],slider_velocity [m/s]",
     [(0.1 * k, k, 0.25) for k in range(30)], {},
     "b.csv: column 'slider_velocity' is constant (0.25 m/s in all 30 samples): a dead channel; remove the column, "
     "or record that sensor again"),
    ("dead channel, all NaN", "time [ms],slider_displacement [mm],slider_velocity [m/s]",
     [(0.1 * k, k, "nan") for k in range(30)], {},
     "b.csv: column 'slider_velocity' holds no numbers (all 30 values are NaN or empty): a dead channel"),
    ("gap in the time", "time [ms],slider_displacement [mm]", [(0.1 * k + (500 if k >= 12 else 0), k) for k in range(30)],
     {}, "b.csv:15: time in column 'time' goes from 1.1 to 501.2 ms, a step 5e+03 times the usual one of 0.1 ms "
     "(1 such step(s)); samples are missing there or the time changes unit (e.g. s written as ms): "
     "fix the time column, or cut the record there"),
    ("time unit changes", "time [ms],slider_displacement [mm]",
     [(0.1 * k * (1e3 if k >= 20 else 1.0), k) for k in range(30)], {},
     "b.csv:23: time in column 'time' goes from 1.9 to 2000 ms"),
    ("header only", "time [ms],slider_displacement [mm]", [], {},
     "b.csv: no samples below the header; write one row of numbers per sample"),
    ("decimal comma", "time [ms];slider_displacement [mm]", [(f"{k};{k // 2},5",) for k in range(30)], {},
     "b.csv:3: column 'slider_displacement': '0,5' is not a number; write decimals with a point (0.5, not 0,5)"),
]


@pytest.mark.parametrize("case, header, rows, options, message", BAD, ids=[case[0] for case in BAD])
def test_bad_data_names_the_file_the_place_and_the_fix(tmp_path, case, header, rows, options, message):
    path = write_csv(tmp_path / "b.csv", header, rows)
    with pytest.raises(MeasuredDataError) as info:
        read_measured(path, UNITS, **options)
    assert isinstance(info.value, ClearsimError)  # the CLI turns it into one message and exit code 2
    assert message in str(info.value)
    assert str(path) in str(info.value)


def test_semicolons_tabs_a_bom_and_an_empty_trailing_column_are_read(tmp_path):
    for name, text in [("semicolon", "time [ms];slider_displacement [mm]\n" + "".join(f"{k};{2 * k}\n" for k in range(30))),
                       ("tab", "time [ms]\tslider_displacement [mm]\n" + "".join(f"{k}\t{2 * k}\n" for k in range(30))),
                       ("bom", "\ufefftime [ms],slider_displacement [mm]\n" + "".join(f"{k},{2 * k}\n" for k in range(30))),
                       ("trailing", "time [ms],slider_displacement [mm],\n" + "".join(f"{k},{2 * k},\n" for k in range(30)))]:
        path = tmp_path / f"{name}.csv"
        path.write_text(text, encoding="utf-8")
        data = read_measured(path, UNITS)
        assert data.values["slider_displacement"][3] == pytest.approx(6e-3), name
        assert data.time[3] == pytest.approx(3e-3), name


def test_a_text_column_that_names_no_sensor_is_left_out(tmp_path):
    path = write_csv(tmp_path / "b.csv", "time [ms],slider_displacement [mm],operator", [(k, k, "anna") for k in range(30)])
    assert read_measured(path, UNITS).ignored == ["operator"]


def test_bytes_that_are_not_utf8_name_the_line(tmp_path):
    path = tmp_path / "b.csv"
    path.write_bytes(b"# bench\ntime [ms],slider_displacement [\xb5m]\n" + b"".join(b"%d,%d\n" % (k, k) for k in range(30)))
    with pytest.raises(MeasuredDataError, match=r"b\.csv:2: byte 0xb5 is not UTF-8 text .*save the record as UTF-8 CSV"):
        read_measured(path, UNITS)


def test_a_file_of_separators_only(tmp_path):
    path = tmp_path / "b.csv"
    path.write_text(",,,\n,,\n,,,\n")
    with pytest.raises(MeasuredDataError, match="b.csv: the file holds only separators, no header or numbers"):
        read_measured(path, UNITS)


def test_a_folder_is_not_a_record(tmp_path):
    with pytest.raises(MeasuredDataError, match="is a folder; give the measured record itself"):
        read_measured(tmp_path, UNITS)


def test_a_damaged_hdf5_record(tmp_path):
    path = tmp_path / "bench.h5"
    with h5py.File(path, "w") as f:
        f.create_dataset("time", data=np.arange(3000.0))
        f.create_dataset("slider_displacement", data=np.arange(3000.0))
    path.write_bytes(path.read_bytes()[:3000])
    with pytest.raises(MeasuredDataError, match="bench.h5: not a readable HDF5 file|bench.h5: the HDF5 file is damaged"):
        read_measured(path, UNITS)


def test_a_clearsim_result_flagged_incomplete_is_not_a_record(tmp_path):
    result = tmp_path / "run.h5"
    with h5py.File(result, "w") as f:
        f.attrs["clearsim_version"], f.attrs["complete"], f.attrs["status"] = "0", False, "interrupted"
        f.create_dataset("time", data=np.linspace(0, 1e-3, 30)).attrs["unit"] = "s"
        f.create_dataset("sensors/slider_displacement", data=np.arange(30.0)).attrs["unit"] = "m"
    with pytest.raises(MeasuredDataError, match=r"run.h5: a clearsim result flagged incomplete \(complete = false, "
                                                r"status: interrupted\); .*run it to the end"):
        read_measured(result, UNITS)


def test_missing_file(tmp_path):
    with pytest.raises(MeasuredDataError, match="no such file; check the path of the measured data"):
        read_measured(tmp_path / "absent.csv", UNITS)


def test_bad_mapping_text():
    with pytest.raises(MeasuredDataError, match="expected column=value"):
        parse_mapping(["Weg"])
