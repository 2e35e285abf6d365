from pathlib import Path

import pytest
from pydantic import ValidationError

from poseintegrity.config import load_params
from poseintegrity.localization.params import ExtractParams

PARAMS_YAML = Path(__file__).parents[2] / "params.yaml"


def test_yaml_section_validates_with_paper_tolerances():
    params = load_params(PARAMS_YAML)
    assert params.protocol.tolerance_names == ["2mm_3deg", "4mm_10deg"]
    assert params.protocol.pnp_method == "usac_magsac" and params.extract.pnp_methods[0] == "epnp"


@pytest.mark.parametrize(
    "bad, key",
    [
        ({"ratio_test": 1.5}, "ratio_test"),
        ({"sift": {"sigma": -1}}, "sift.sigma"),
        ({"pnp_methods": ["dls"]}, "pnp_methods.0"),
        ({"n_jobs": 0}, "n_jobs"),
        ({"ransac_typo": 3}, "ransac_typo"),
    ],
)
def test_bad_values_raise_naming_the_key(bad, key):
    with pytest.raises(ValidationError) as error:
        ExtractParams.model_validate(bad)
    locations = [".".join(str(part) for part in item["loc"]) for item in error.value.errors()]
    assert key in locations
