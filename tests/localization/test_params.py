import pytest
import yaml
from pydantic import ValidationError

from poseintegrity.localization.params import ExtractParams, tolerance_name

PAPER_SECTION = """
clahe: {clip_limit: 2.0, tile_grid: 8}
sift: {n_features: 0, n_octave_layers: 3, contrast_threshold: 0.04, edge_threshold: 10.0, sigma: 1.6}
ratio_test: 0.8
reprojection_threshold_px: 4.0
pnp_methods: [epnp, p3p, ap3p, sqpnp, iterative]
tolerances: [[2, 3], [4, 10]]
n_jobs: 2
"""


def test_yaml_section_validates_with_paper_tolerances():
    params = ExtractParams.model_validate(yaml.safe_load(PAPER_SECTION))
    assert [tolerance_name(t) for t in params.tolerances] == ["2mm_3deg", "4mm_10deg"]
    assert params.pnp_method == "usac_magsac"


@pytest.mark.parametrize(
    "bad, key",
    [
        ({"ratio_test": 1.5}, "ratio_test"),
        ({"sift": {"sigma": -1}}, "sift.sigma"),
        ({"pnp_methods": ["dls"]}, "pnp_methods.0"),
        ({"tolerances": [[2, -3]]}, "tolerances"),
        ({"n_jobs": 0}, "n_jobs"),
        ({"ransac_typo": 3}, "ransac_typo"),
    ],
)
def test_bad_values_raise_naming_the_key(bad, key):
    with pytest.raises(ValidationError) as error:
        ExtractParams.model_validate(bad)
    locations = [".".join(str(part) for part in item["loc"]) for item in error.value.errors()]
    assert key in locations
