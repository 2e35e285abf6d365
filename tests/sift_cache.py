"""Stage 02's SIFT features of one dataset copied from a data_dir where they were computed into another holding the
same images: tests of what happens after SIFT (bad frames, ground truth) need not run SIFT on every image again."""

import shutil
from pathlib import Path

from poseintegrity.params.extract import ExtractParams

# The cache entries of stage 02 beside the SIFT features (poseintegrity.localization.extract): matches and board
# evidence, PnP results and M_t, all computed again in the copy.
LATER_THAN_SIFT = (".evidence.npz", ".pnp.npz", "M_t.npz")


def copy_sift_features(source: Path, target: Path, dataset: str, params: ExtractParams) -> None:
    """Copy the SIFT features of ``dataset`` from ``source``'s features folder into ``target``'s. Each entry is keyed
    by its image's bytes (and the CLAHE and SIFT settings): an image that differs in ``target`` is read and its
    features computed anew."""
    shutil.copytree(Path(source) / params.features_dir / dataset, Path(target) / params.features_dir / dataset,
                    ignore=lambda _, names: [name for name in names if name.endswith(LATER_THAN_SIFT)])
