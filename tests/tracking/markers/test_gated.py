import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from poseintegrity.tracking.markers.gated import match_gated

from tracking import reference_matching as reference
from tracking.marker_scenes import small_motion


@settings(deadline=None, max_examples=50)
@given(seed=st.integers(0, 2**32 - 1), n_missing=st.integers(0, 1), n_phantoms=st.integers(0, 2))
def test_gated_follows_a_small_motion_among_phantoms(seed, n_missing, n_phantoms):
    _, previous, with_phantoms, truth = small_motion(seed, n_missing, n_phantoms)
    np.testing.assert_array_equal(match_gated(with_phantoms, previous, gate_m=0.02), truth)


def test_gated_ties_and_crowded_gates_go_to_scipy_as_before():
    """Points within the gate of two markers, markers with two points in the gate, exact ties (a point midway, a
    duplicated point) and predictions beyond every gate: the cases the compiled matcher hands to scipy."""
    rng = np.random.default_rng(2)
    for _ in range(2000):
        m, n = int(rng.integers(1, 6)), int(rng.integers(0, 8))
        predicted = rng.normal(0.0, 0.02, (m, 3))
        points = np.vstack([predicted[rng.integers(m, size=n)] + rng.normal(0.0, rng.choice([0.0, 0.005, 0.02]), (n, 3)),
                            (predicted[:1] + predicted[-1:]) / 2])
        if rng.random() < 0.3:
            points = np.vstack([points, points[:1]])
        gate = float(rng.choice([0.005, 0.02, 0.05, 2e6]))
        np.testing.assert_array_equal(match_gated(points, predicted, gate_m=gate), reference.match_gated(points, predicted, gate_m=gate))
