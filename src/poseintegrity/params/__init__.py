"""The schema of ``params.yaml``: one module per stage's section, each beside the others, importing none of the
code that runs the stages (:mod:`poseintegrity.config` reads them; the stages import what they take).

    generate.py     ``generate`` (stage 01): the worlds, their scenes and trajectories; camera.py its camera, sensor,
                    capture, calibration and boards; robot.py its UR5e and how its poses err
    extract.py      ``extract`` (stages 02 and 05): CLAHE, SIFT, matching, PnP-RANSAC, the ground truth's checks
    fit.py          ``fit`` (stage 03): the artifact models and their fits; model_names.py names them
    predict.py      ``predict`` (stage 04): the predictors and their sweeps
    track.py        ``track`` (stage 06): marker detection, matching, the filter and the simulation study

The two sections every stage reads keep their schemas lower down, beside what they share: ``protocol``
(:mod:`poseintegrity.protocol`, the facts of Windsor et al.'s protocol that stages 01-05 share, which the other
sections are checked against) and ``parallel`` (:class:`poseintegrity.parallel.ParallelParams`).
"""
