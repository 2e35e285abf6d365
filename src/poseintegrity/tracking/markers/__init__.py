"""Markers in a frame (Black and Salcudean II-B, II-D, Alg. 1-4): detection in the IR + depth frame, correspondence
to the tool geometry, Kabsch, and the tool geometry checks.

    detection.py         II-B: threshold, contours, shape tests, centroid, depth, unprojection
    blob_shape.py        II-B: a blob's area, circularity and convexity, and its pixels
    blob_split.py        ours: two touching markers in one blob, cut by depth or as two discs
    depth_readings.py    II-B: a marker's depth from its pixels' readings, compiled
    correspondence.py    II-D: the matching pipeline (gated assignment, Alg. 2, Alg. 3 and their fallbacks)
    frobenius.py         Alg. 1: closest previous points by the Frobenius norm (appendix B)
    voting.py            Alg. 2: Euclidean-distance voting with outlier rejection
    brute_force.py       Alg. 3: every map of markers to points fitted with Kabsch, the best kept
    gated.py             ours: optimal assignment to the predicted markers within a distance gate
    consistency.py       whether a match fits the rigid geometry; the checks every matcher shares
    summation.py         numpy's norms, sums and argmin compiled in numpy's order (the matchers' rounding)
    kabsch.py            Alg. 4: Kabsch-Umeyama pose from corresponding points
    geometry.py          II-B: the marker body's size, pairwise distances, skew matrices, rigid transforms
    tools.py             ours: a set of tools checked (>= 3 markers each, distinct distances across tools)
"""
