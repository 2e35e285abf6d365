"""How many 2D-3D correspondences a camera pose needs.

A leaf of plain Python: localization's PnP refuses fewer (:mod:`poseintegrity.localization.pnp`), and the error
predictors read a forecast inlier count below it as no pose (:mod:`poseintegrity.prediction.error_predictors`).
"""

MIN_CORRESPONDENCES = 4  # a unique pose needs 4 points; P3P with 3 leaves up to 4 solutions
