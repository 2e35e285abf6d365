from pathlib import Path

import pytest
import yaml
from pydantic import ValidationError

from poseintegrity.localization.params import ExtractParams, tolerance_name

PARAMS_YAML = Path(__file__).parents[2] / "params.yaml"


def test_yaml_section_validates_with_paper_tolerances():
    params = ExtractParams.model_validate(yaml.safe_load(PARAMS_YAML.read_text())["extract"])
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
