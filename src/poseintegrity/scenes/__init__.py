"""Stage 01: the rendered world of Windsor et al. IV-D. The ``generate`` section's schema is
:mod:`poseintegrity.params.generate`.

    dataset.py            the stage: every world planned, its images taken, its datasets written (``generate``)
    world_plan.py         every world planned before rendering: checked, its trips, robot drives, camera calibration
    world_checks.py       whether a world can give its datasets: sessions laid out, targets in the model views
    trips.py              the datasets a world renders and each one's commanded model pair and stops
    world_cache.py        a session's scene and renderable geometry, built once per process
    shots.py              one shot per camera visit: rendered once, exposed per image, the PNG files written
    dataset_files.py      a dataset's frames.parquet, meta.json (checked) and camera.yaml, its folder renamed
    catalog.py            scenes laid out: targets, clutter, the table, their textures
    scene_boards.py       a scene's ground-truth boards: lying flat or on posts, as printed sheets with their posts
    printed_boards.py     a printed board's scale and bow, and its size as the lab measured it
    board_plan.py         placement planned: the single board or pair serving most trajectories (ranking, pairs)
    board_candidates.py   the candidate boards: sizes, places on a grid about the aim point, turns and tilts
    board_criteria.py     which candidates serve which poses: corners found, not covered, in focus
    board_sigma.py        a board pose's predicted sigma_t from its corners found, and stage 02's margin on it
    board_placement.py    placement facing_camera: one board facing the model camera, most of it in view
    board_stand.py        a board on its post: where it stands, the grid of places, clutter that would cover it
    image_polygons.py     where points, boards and targets fall in the image: projections, hulls, masks, overlaps
    trajectories.py       the protocol's camera poses: the model pair, arcs about the target, lines away from it
    robot.py              the UR5e (on :mod:`poseintegrity.kinematics`) turning commanded poses into actual ones
    acquisition.py        a dataset's visits: where the robot lands, and each image's ring-down path
    ringdown.py           the camera's vibration after a stop: one damped mode
    camera.py             the eye-in-hand camera as rendered (true intrinsics and lens), look_at
    optics.py             the lens between radiance and sensor: depth of field and the lens' own blur
    renderer.py           the software renderer: z-buffer, shading, textures, foam relief, the sensor's exposure
    mesh.py               triangle meshes: primitives, printed sheets, meshes read from files
    scapula.py            the anatomical scapula phantom, pre-drilled in the glenoid
    foam.py               bone foam's surface as a solid texture (its pores and bumps)
    textures.py           procedural albedo maps, image files as overrides, the renderer's atlas
    calibration_views.py  the calibration session: a ChArUco board in many poses, rendered and calibrated
    inspect.py            what a reader checks of the rendered world: disk size, calibration, boards, targets
"""
