"""Marker tracking after Black and Salcudean, "Robust Object Pose Tracking for Augmented Reality Guidance and
Teleoperation", IEEE Transactions on Instrumentation and Measurement, 2024, DOI 10.1109/TIM.2024.3398108: IR marker
detection, point correspondence, Kabsch, square-root UKF with gyro fusion, and the simulation study of their
sections II-F and III.  Recorded frames (a HoloLens 2 recording) go through :func:`read_recording` and
:func:`track_recording`; several tools through :class:`MultiToolTracker`.

Sub-packages (paper section -> module):
    markers/      II-B  detection       :mod:`.markers.detection` (threshold, contours, shape tests, touching-blob split,
                                        depth, unprojection)
                  II-D  Alg. 1, 2, 3    :mod:`.markers.correspondence` (+ gated optimal assignment)
                  Alg. 4                :mod:`.markers.kabsch`
                  II-B  tool geometry   :mod:`.markers.geometry`, :mod:`.markers.tools` (several tools, ours)
    filter/       II-E  eqs. 3-30       :mod:`.filter.model` (state, process model, P_proc, P_mes)
                  Alg. 5                :mod:`.filter.srukf`, :mod:`.filter.cholesky`, :mod:`.filter.unscented`;
                                        reference :mod:`.filter.ukf`
                  loop                  :mod:`.filter.tracker` (+ innovation gate, ours), :mod:`.filter.multi_tool`
    simulation/   II-B  sensor frames   :mod:`.simulation.frames` (AHAT-like IR + depth synthesis, ours)
                  II-F  motion          :mod:`.simulation.motion` (motion (a) paper-like and (b) stress),
                                        :mod:`.simulation.pace` (motion (c), the paper's pace, from its lag and errors),
                                        :mod:`.simulation.simulate` (a simulated recording through the pipeline)
                  II-F  errors          :mod:`.simulation.errors` (the paper's per-axis / Euler RMS beside norm /
                                        geodesic)
    io/           input                 :mod:`.io.recording` (a folder of recorded frames -> pose table),
                                        :mod:`.io.hl2_recordings` (HoloLens 2 AHAT recordings of StreamRecorder
                                        and hl2ss -> a recording folder), :mod:`.io.tool_files`
    experiments/  III   results         stage 06's experiments, one module each: :mod:`.experiments.accuracy`
                                        (III-A/B, occlusion), :mod:`.experiments.success` (III-C),
                                        :mod:`.experiments.paper_pace` (III-A at the paper's pace),
                                        :mod:`.experiments.filter_runs`, :mod:`.experiments.lag`,
                                        :mod:`.experiments.timing` (Table I), :mod:`.experiments.robustness` (ours),
                                        :mod:`.experiments.small_blobs` (ours: 8-20 px markers),
                                        :mod:`.experiments.peers` (filterpy, pykalman); :mod:`.experiments.study`
                                        runs them all
    replay        command line: a recording + a tool file -> pose table and summary
"""

import lazy_loader

# Names resolve on first use, so that importing one module of the package (its params schema, say) does not
# import all of them: the stage runner and every worker process import only what they run.
__getattr__, __dir__, __all__ = lazy_loader.attach(
    __name__,
    submod_attrs={
        "markers.correspondence": ["match_brute_force", "match_frobenius", "match_gated", "match_markers",
                                   "match_voting"],
        "markers.detection": ["detect_markers", "validate_frame"],
        "markers.kabsch": ["kabsch", "pose_from_points"],
        "markers.tools": ["ToolError", "check_tools"],
        "filter.srukf": ["SquareRootUKF"],
        "filter.ukf": ["UnscentedKalmanFilter"],
        "filter.tracker": ["MarkerTracker"],
        "filter.multi_tool": ["MultiToolTracker"],
        "io.hl2_recordings": ["convert_hl2ss", "convert_stream_recorder", "read_hl2ss_ahat", "read_hl2ss_calibration"],
        "io.recording": ["Recording", "RecordingError", "RecordingWriter", "read_recording", "track_recording"],
        "io.tool_files": ["read_tools", "write_tools"],
        "replay": ["replay_summary"],
    },
)
