"""The schema of ``params.yaml``: one module per section, each beside the others, importing none of the code that
runs the stages (:mod:`poseintegrity.config` reads them; the stages import what they take).

    protocol.py     ``protocol``: the facts of Windsor et al.'s protocol that stages 01-05 share (tolerances,
                    sampled stops, the PnP method), which the other sections are checked against
    parallel.py     ``parallel``: where the per-frame and per-dataset tasks run (:mod:`poseintegrity.workers`)
    generate.py     ``generate`` (stage 01): the worlds, their scenes and trajectories
    camera.py       ``generate``'s camera and lens, sensor, capture and calibration session
    boards.py       ``generate``'s printed boards and the scenes' ground-truth board with its placement plan
    robot.py        ``generate``'s UR5e and how its poses err
    extract.py      ``extract`` (stages 02 and 05): CLAHE, SIFT, matching, PnP-RANSAC, the ground truth's checks
    fit.py          ``fit`` (stage 03): the artifact models and their fits
    model_names.py  the artifact models' names, shared by ``fit`` and ``predict``
    predict.py      ``predict`` (stage 04): the predictors and their sweeps
    track.py        ``track`` (stage 06): marker detection, matching, the filter and the simulation study
    population.py   ``population``: the population of rendered worlds (population/dvc.yaml)
"""
