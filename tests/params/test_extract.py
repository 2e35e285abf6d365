"""The ``extract`` section: params.yaml is the only source of its values, and every bad value is refused before
any work with its key named."""

import copy

import pytest

from params_cases import refusal
from poseintegrity.config import ParamsError, parse_params
from poseintegrity.params.extract import ClaheParams, ConsensusParams, ExtractParams, RealismParams, SiftParams


def test_tiny_section_validates_beside_the_paper_protocol(tiny_params):
    assert tiny_params.protocol.tolerance_names == ["2mm_3deg", "4mm_10deg"]
    assert tiny_params.protocol.pnp_method == "usac_magsac"
    assert tiny_params.protocol.pnp_method not in tiny_params.extract.pnp_methods


@pytest.mark.parametrize("schema", [ExtractParams, ClaheParams, SiftParams, RealismParams, ConsensusParams])
def test_no_field_has_a_default_that_could_disagree_with_params_yaml(schema):
    assert [name for name, field in schema.model_fields.items() if not field.is_required()] == []


def test_every_key_of_the_section_must_be_set(tiny_raw):
    for key in list(tiny_raw["extract"]):
        raw = copy.deepcopy(tiny_raw)
        del raw["extract"][key]
        with pytest.raises(ParamsError, match=rf"extract\.{key}: Field required"):
            parse_params(raw)


# (dotted key, bad value, the key the error must name)
BAD_VALUES = [
    ("extract.ratio_test", 1.0, "extract.ratio_test"),  # keeps every match
    ("extract.ratio_test", 0.0, "extract.ratio_test"),
    ("extract.ratio_test", float("nan"), "extract.ratio_test"),
    ("extract.model_max_reprojection_px", 0.0, "extract.model_max_reprojection_px"),
    ("extract.model_max_reprojection_px", 50.0, "extract.model_max_reprojection_px"),
    ("extract.reprojection_threshold_px", -1.0, "extract.reprojection_threshold_px"),
    ("extract.reprojection_threshold_px", 25.0, "extract.reprojection_threshold_px"),
    ("extract.ransac_confidence", 1.0, "extract.ransac_confidence"),
    ("extract.usac_max_iterations", 0, "extract.usac_max_iterations"),
    ("extract.usac_max_iterations", 10**9, "extract.usac_max_iterations"),
    ("extract.ransac_budget_inlier_ratio", 0.0, "extract.ransac_budget_inlier_ratio"),
    ("extract.ransac_budget_inlier_ratio", 1.5, "extract.ransac_budget_inlier_ratio"),
    ("extract.ransac_budget_inlier_ratio", 0.05, "extract.ransac_budget_inlier_ratio"),  # 22 million samples of 5
    ("extract.usac_refine_lm", "maybe", "extract.usac_refine_lm"),
    ("extract.pnp_methods", ["dls"], "extract.pnp_methods.0"),
    ("extract.pnp_methods", [], "extract.pnp_methods"),
    ("extract.pnp_methods", ["epnp", "p3p", "epnp"], "extract.pnp_methods"),  # run twice
    ("extract.pnp_methods", ["usac_magsac", "epnp"], "extract.pnp_methods"),  # protocol.pnp_method: stage 02's
    ("extract.seed", -1, "extract.seed"),
    ("extract.seed", 2**64, "extract.seed"),
    ("extract.features_dir", "", "extract.features_dir"),
    ("extract.datasets", [], "extract.datasets"),  # nothing to do: null means every dataset
    ("extract.datasets", ["scene_a_arc000", "scene_a_arc000"], "extract.datasets"),  # extracted twice
    ("extract.datasets", [" "], "extract.datasets"),
    ("extract.n_jobs", 2, "extract.n_jobs"),  # gone: parallel.n_jobs is the only one
    ("extract.ransac_typo", 3, "extract.ransac_typo"),
    ("extract.clahe.clip_limit", 0.0, "extract.clahe.clip_limit"),
    ("extract.clahe.tile_grid", 0, "extract.clahe.tile_grid"),
    ("extract.sift.n_features", -1, "extract.sift.n_features"),
    ("extract.sift.n_octave_layers", 0, "extract.sift.n_octave_layers"),
    ("extract.sift.contrast_threshold", 0.0, "extract.sift.contrast_threshold"),
    ("extract.sift.edge_threshold", 0.5, "extract.sift.edge_threshold"),
    ("extract.sift.sigma", -1.0, "extract.sift.sigma"),
    ("extract.sift.sigma", float("inf"), "extract.sift.sigma"),
    ("extract.realism.max_nfev", 5, "extract.realism.max_nfev"),
    ("extract.consensus.n_bootstrap", -1, "extract.consensus.n_bootstrap"),
    ("extract.consensus.n_bootstrap", 2.0, "extract.consensus.n_bootstrap"),  # a count
    ("extract.consensus.n_bootstrap", 10**6, "extract.consensus.n_bootstrap"),
    ("extract.consensus.n_reruns", -1, "extract.consensus.n_reruns"),
    ("extract.consensus.n_reruns", True, "extract.consensus.n_reruns"),
    ("extract.consensus.elsewhere_mm", 0.0, "extract.consensus.elsewhere_mm"),  # every re-run would be elsewhere
    ("extract.consensus.elsewhere_mm", float("nan"), "extract.consensus.elsewhere_mm"),
    ("extract.consensus.elsewhere_deg", -1.5, "extract.consensus.elsewhere_deg"),
    ("extract.consensus.elsewhere_deg", 180.0, "extract.consensus.elsewhere_deg"),
    ("extract.consensus.n_boot", 16, "extract.consensus.n_boot"),
]


@pytest.mark.parametrize("key, value, expected", BAD_VALUES)
def test_bad_value_names_its_key(tiny_raw, key, value, expected):
    assert expected in refusal(tiny_raw, key, value)
