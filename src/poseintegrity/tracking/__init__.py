"""Marker tracking after Black and Salcudean, "Robust Object Pose Tracking for Augmented Reality Guidance and
Teleoperation", IEEE Transactions on Instrumentation and Measurement, 2024, DOI 10.1109/TIM.2024.3398108: IR marker
detection, point correspondence, Kabsch, square-root UKF with gyro fusion, and the simulation study of their
sections II-F and III.  Recorded frames (a HoloLens 2 recording) go through :func:`read_recording` and
:func:`track_recording`; several tools through :class:`MultiToolTracker`.

Sub-packages, each mapping its modules to the paper's sections in its own docstring:

    markers/       II-B detection, II-D correspondence (Alg. 1-3), Alg. 4 Kabsch, the tool geometry
    filter/        II-E eqs. 3-30 and Alg. 5: the SR-UKF and the plain UKF, the trackers, a recording replayed
    simulation/    II-B, II-F: sensor frames, motions (a)-(c), simulated recordings, the paper's error measures
    io/            recorded input: recording folders, HoloLens 2 recordings, tool files
    experiments/   section III: one module per experiment; study.py runs them all
    replay.py      command line: a recording + a tool file -> pose table and summary
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
