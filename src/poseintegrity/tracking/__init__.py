"""Marker tracking after Black and Salcudean, "Robust Object Pose Tracking for Augmented Reality Guidance and
Teleoperation", IEEE Transactions on Instrumentation and Measurement, 2024, DOI 10.1109/TIM.2024.3398108: IR marker
detection, point correspondence, Kabsch, square-root UKF with gyro fusion, and the simulation study of their
sections II-F and III.  Recorded frames (a HoloLens 2 recording) go through :func:`read_recording` and
:func:`track_recording`; several tools through :class:`MultiToolTracker`.

    markers/               markers in a frame and their correspondence to the tool geometry (II-B, II-D, Alg. 1-4)
      detection.py           II-B: threshold, contours, shape tests, centroid, depth, unprojection
      blob_shape.py          II-B: a blob's area, circularity and convexity, and its pixels
      blob_split.py          ours: two touching markers in one blob, cut by depth or as two discs
      depth_readings.py      II-B: a marker's depth from its pixels' readings, compiled
      correspondence.py      II-D: the matching pipeline (gated assignment, Alg. 2, Alg. 3 and their fallbacks)
      frobenius.py           Alg. 1: closest previous points by the Frobenius norm (appendix B)
      voting.py              Alg. 2: Euclidean-distance voting with outlier rejection
      brute_force.py         Alg. 3: every map of markers to points fitted with Kabsch, the best kept
      gated.py               ours: optimal assignment to the predicted markers within a distance gate
      consistency.py         whether a match fits the rigid geometry; the checks every matcher shares
      summation.py           numpy's norms, sums and argmin compiled in numpy's order (the matchers' rounding)
      kabsch.py              Alg. 4: Kabsch-Umeyama pose from corresponding points
      geometry.py            II-B: the marker body's size, pairwise distances, skew matrices, rigid transforms
      tools.py               ours: a set of tools checked (>= 3 markers each, distinct distances across tools)
    filter/                the filter and the tracking loop (II-E, Alg. 5)
      model.py               eqs. 3-30: state, process model, P_proc, P_mes
      unscented.py           what both unscented filters share: sigma points, weights, the model calls
      srukf.py               Alg. 5: the square-root UKF
      cholesky.py            Alg. 5's triangular factors: QR-based factor, rank-1 update and downdate
      ukf.py                 the plain UKF the SR-UKF is checked against
      tracker.py             one tool: correspondence, partial updates, gyro, innovation gate (ours), restarts
      multi_tool.py          ours: several tools fed by the same frames
      recording_replay.py    a recording folder through detection and the trackers, into a pose table
    simulation/            the simulation study's world (II-B, II-F)
      frames.py              ours: AHAT-like IR + depth frames with markers, phantoms and noise
      motion.py              II-F: motion (a) paper-like and (b) stress, and the sensor timeline
      pace.py                motion (c): the paper's pace, from its lag and errors
      simulate.py            a simulated recording through the pipeline, without and with the filter
      errors.py              II-F: the paper's per-axis / Euler RMS beside norm / geodesic errors
    io/                    recorded input
      recording.py           the recording folder (frames, lookup table, gyro, manifest), read and written
      hl2_recordings.py      HoloLens 2 AHAT recordings of StreamRecorder and hl2ss -> a recording folder
      tool_files.py          tool files (JSON, CSV) read and written
      timestamps.py          the clock's range, shared by the recording folder and the trackers
    experiments/           stage 06's experiments (III), one module each
      study.py               run_study: every experiment below, on workers
      accuracy.py            III-A/B: accuracy and occlusion, noise against lag, the published sigmas
      success.py             III-C: success rates of motions (a) and (b), 4 or 3 markers, two tools (ours)
      paper_pace.py          III-A at the paper's pace (motion (c))
      filter_runs.py         the filter runs, each made once over the recordings that need it
      lag.py                 II-F: the filter's lag behind the unfiltered chain
      intervals.py           ours: block-resampled intervals of the success rates and the accuracy
      compute_time.py        Table I: the computation times of the pipeline's subroutines
      robustness.py          ours: a 10 m jump, a recording written to disk and replayed
      small_blobs.py         ours: 8-20 px markers, detected or not
      peers.py               filterpy's and pykalman's UKFs on our model, for agreement and speed
    replay.py              command line: a recording + a tool file -> pose table and summary
"""

import lazy_loader

# Names resolve on first use, so that importing one module of the package (its params schema, say) does not
# import all of them: the stage runner and every worker process import only what they run.
__getattr__, __dir__, __all__ = lazy_loader.attach(
    __name__,
    submod_attrs={
        "markers.brute_force": ["match_brute_force"],
        "markers.correspondence": ["match_markers"],
        "markers.frobenius": ["match_frobenius"],
        "markers.gated": ["match_gated"],
        "markers.voting": ["match_voting"],
        "markers.detection": ["detect_markers", "validate_frame"],
        "markers.kabsch": ["kabsch", "pose_from_points"],
        "markers.tools": ["ToolError", "check_tools"],
        "filter.srukf": ["SquareRootUKF"],
        "filter.ukf": ["UnscentedKalmanFilter"],
        "filter.tracker": ["MarkerTracker"],
        "filter.multi_tool": ["MultiToolTracker"],
        "filter.recording_replay": ["track_recording"],
        "io.hl2_recordings": ["convert_hl2ss", "convert_stream_recorder", "read_hl2ss_ahat", "read_hl2ss_calibration"],
        "io.recording": ["Recording", "RecordingError", "RecordingWriter", "read_recording"],
        "io.tool_files": ["read_tools", "write_tools"],
        "replay": ["replay_summary"],
    },
)
