"""What `validate` and stage 01 say before any run: stops beyond the protocol's range end are refused naming the key
to change (and the value that would hold them), in validate, in materialize (stage 01) and in stage 03's series;
a weak model pair is warned about with its baseline and the depth error it gives at the target (Z^2 delta / (f b)).
The folders are written by a user's own script (foreign_datasets.py), not by the exporter."""

from __future__ import annotations

import pandas as pd
import pytest
import yaml

from foreign_datasets import Folder, write_folder
from poseintegrity.artifact_models.series import dataset_series
from poseintegrity.config import load_params
from poseintegrity.errors import ArgumentError
from poseintegrity.recorded.materialize import materialize_source
from poseintegrity.recorded.model_pair import pair_geometry
from poseintegrity.recorded.reader import RecordedFormatError, read_recorded
from recorded_tools import run
from repository import ROOT

TINY = ROOT / "tests" / "params_tiny.yaml"


def params_file(tmp_path, **protocol) -> str:
    path = tmp_path / "mine.yaml"
    path.write_text(yaml.safe_dump({"extends": str(TINY), "protocol": protocol}))
    return str(path)


def test_stops_beyond_the_arc_span_are_refused_naming_the_key_and_the_value_that_holds_them(tmp_path):
    folder = write_folder(tmp_path / "rec", Folder("wide_arc", stops=(10.0, 50.0, 90.0), size=(160, 100)))
    status, _, stderr = run(["validate", str(folder), "--params", str(TINY)])
    assert status == 2
    assert "stops.csv: field theta_deg: the stops reach 90 deg, beyond protocol.arc_span_deg = 45 deg" in stderr
    assert "set protocol.arc_span_deg to at least 90" in stderr
    with pytest.raises(RecordedFormatError, match=r"protocol\.arc_span_deg to at least 90"):  # stage 01 likewise
        materialize_source(tmp_path / "rec", tmp_path / "data", load_params(TINY).protocol)
    assert not (tmp_path / "data" / "datasets" / "index.parquet").exists()
    status, stdout, _ = run(["validate", str(folder), "--params", params_file(tmp_path, arc_span_deg=90.0)])
    assert status == 0 and "wide_arc: ok" in stdout and "mine.yaml" in stdout


def test_a_line_beyond_its_length_and_a_negative_stop_are_refused(tmp_path):
    line = write_folder(tmp_path / "rec", Folder("long_line", trajectory="line", stops=(0.0, 100.0, 200.0),
                                                 size=(160, 100)))
    status, _, stderr = run(["validate", str(line), "--params", str(TINY)])
    assert status == 2 and "the stops reach 200 mm, beyond protocol.line_length_mm = 150 mm" in stderr
    table = line / "stops.csv"
    table.write_text(table.read_text().replace(",0.0,", ",-5.0,", 1))
    status, _, stderr = run(["validate", str(line), "--params", params_file(tmp_path, line_length_mm=300.0)])
    assert status == 2 and "a stop at -5 mm: positions start at 0" in stderr


def test_stage_03_names_the_range_end_key_of_a_table_beyond_it():
    rows = pd.DataFrame({"dataset": "d", "trajectory": "arc", "stop": [0, 1], "image": 0, "theta_deg": [10.0, 60.0],
                         "x_mm": 0.0, "method": "usac_magsac", "n_inliers": [50.0, 20.0], "world": "w"})
    with pytest.raises(ArgumentError, match=r"the range end protocol\.arc_span_deg: set protocol\.arc_span_deg"):
        dataset_series(rows, "usac_magsac", load_params(TINY).protocol)


@pytest.mark.parametrize("baseline_mm", [6.0, 20.0])
def test_the_model_pairs_depth_error_is_z_squared_delta_over_f_b(tmp_path, baseline_mm):
    """loc_synthetic's scene: the model camera looks at the plane fronto-parallel from 260 mm, f = 600 px; the pair
    is moved along camera x by the baseline, so Z = 260 mm at every target point and b is the whole baseline."""
    folder = write_folder(tmp_path / "rec", Folder("pair", size=(640, 400), baseline_mm=baseline_mm))
    extract = load_params(TINY).extract
    geometry = pair_geometry(read_recorded(folder), extract)
    assert geometry.baseline_mm == pytest.approx(baseline_mm) and geometry.across_mm == pytest.approx(baseline_mm)
    assert geometry.focal_px == 600.0 and geometry.n_points >= 20
    assert geometry.distance_mm == pytest.approx(260.0, rel=0.02)  # triangulated with the recorded baseline
    expected = 260.0**2 * extract.reprojection_threshold_px / (600.0 * baseline_mm)
    assert geometry.depth_error_mm == pytest.approx(expected, rel=0.05)
    status, stdout, stderr = run(["validate", str(folder), "--params", str(TINY)])
    assert status == 0 and "pair: ok" in stdout
    if baseline_mm == 6.0:  # 11.3 mm > the loosest tolerance, 4 mm
        assert "warning:" in stderr and "the model pair is 6 mm apart" in stderr
        assert f"a depth error of {expected:.3g} mm at the target" in stderr.replace("\n", " ")
    else:  # 3.4 mm
        assert "warning" not in stderr
