"""Marker tracking after Black and Salcudean, "Robust Object Pose Tracking for Augmented Reality Guidance and
Teleoperation", IEEE Transactions on Instrumentation and Measurement, 2024, DOI 10.1109/TIM.2024.3398108: IR marker
detection, point correspondence, Kabsch, square-root UKF with gyro fusion, and the simulation study of their
sections II-F and III.  Recorded frames (a HoloLens 2 recording) go through :func:`read_recording` and
:func:`track_recording`; several tools through :class:`MultiToolTracker`.

Module map (paper section -> module):
    II-B  detection      :mod:`detection`       (threshold, contours, shape tests, touching-blob split, depth, unprojection)
          small blobs    :mod:`detection_sweep` (ours: keep rate of 8-20 px markers, phantom rejection)
    II-B  sensor frames  :mod:`frames`          (AHAT-like IR + depth synthesis, ours)
    II-D  Alg. 1, 2, 3   :mod:`correspondence`  (+ gated optimal assignment)
    Alg. 4               :mod:`kabsch`
    II-E  eqs. 3-30      :mod:`model`           (state, process model, P_proc, P_mes)
    Alg. 5               :mod:`srukf`, :mod:`cholesky`, :mod:`unscented`; reference :mod:`ukf`
    II-F  simulation     :mod:`motion` (motion (a) paper-like and (b) stress), :mod:`simulation`
    II-F  errors         :mod:`errors`          (the paper's per-axis / Euler RMS beside norm / geodesic)
    loop                 :mod:`tracker`         (+ innovation gate, ours), :mod:`tools` (several tools, ours)
    input                :mod:`recording`       (a folder of recorded frames -> pose table)
                         :mod:`hl2_recordings`  (HoloLens 2 AHAT recordings of StreamRecorder and hl2ss -> a recording folder)
                         :mod:`replay`          (command line: a recording + a tool file -> pose table and summary)
    peers                :mod:`peers`           (filterpy, pykalman)
    III   results        :mod:`evaluation`
"""

import lazy_loader

# Names resolve on first use, so that importing one module of the package (its params schema, say) does not
# import all of them: the stage runner and every worker process import only what they run.
__getattr__, __dir__, __all__ = lazy_loader.attach(
    __name__,
    submod_attrs={
        "correspondence": ["match_brute_force", "match_frobenius", "match_gated", "match_markers", "match_voting"],
        "detection": ["detect_markers", "validate_frame"],
        "hl2_recordings": ["convert_hl2ss", "convert_stream_recorder", "read_hl2ss_ahat", "read_hl2ss_calibration"],
        "kabsch": ["kabsch", "pose_from_points"],
        "params": ["TrackParams"],
        "recording": ["Recording", "RecordingError", "RecordingWriter", "read_recording", "track_recording"],
        "replay": ["replay_summary"],
        "srukf": ["SquareRootUKF"],
        "tools": ["MultiToolTracker", "ToolError", "read_tools", "write_tools"],
        "tracker": ["MarkerTracker"],
        "ukf": ["UnscentedKalmanFilter"],
    },
)
