"""Recorded localization datasets (Windsor et al., RA-L 2024): real images brought into the pipeline.

A recorded dataset is one folder (its name is the dataset's name) holding::

    dataset.yaml   trajectory: arc | line; ground_truth: board | poses; world (optional, default "recorded");
                   T_cam1_cam0 (optional): the model pair's relative pose as the robot reported it (III-B, IV-D),
                   16 row-major numbers, camera 0 -> camera 1, mm
    camera.yaml    the calibrated camera, ROS camera_info layout: image_width, image_height, camera_matrix,
                   distortion_model plumb_bob (5 coefficients) or rational_polynomial (8), distortion_coefficients
    board.yaml     (ground_truth: board) the ArUco GridBoard in view (IV-C): dictionary, markers_x, markers_y,
                   marker_length_mm, separation_mm, first_id
    model.csv      two rows, the model pair (III-B): file, mask (optional column or empty cell: the whole image is
                   target), T_cam_ref (optional column; required with ground_truth: poses), T_base_cam (optional)
    stops.csv      one row per image: file, stop, theta_deg, x_mm, T_cam_ref, T_base_cam (the last four optional)
    images         anywhere in the folder, named by their path relative to it (PNG, JPEG or TIFF; 8 or 16 bit;
                   mono, BGR or BGRA colour); every image file in the folder must be listed in a table

Conventions. ``T_cam_ref`` is a camera pose as 16 numbers separated by spaces, the row-major 4 x 4 matrix that maps
points of the reference frame (mm) into the camera frame, as the pipeline's ``T_cam_board``; the reference frame is
the board's (``board.getObjPoints()``) or the external tracking system's. A tracker's camera pose T_ref_cam is its
inverse. Stops: ``stop`` is an integer >= 0, rows of one stop follow each other (stop never decreases down the file),
each row one image (the image index is its order within the stop); stops may be irregularly spaced and hold one
image or many. ``theta_deg`` (arcs) is the viewing angle of the image: when the column or a cell is empty it is
computed from the poses, as the angle of the rotation between the model pose (model image 0, where M_t was created)
and the image's pose (III-D); ``x_mm`` (lines) likewise is the distance of the camera centre from the trajectory's
first position (V-A; the first stop's mean camera centre). The position a trajectory does not vary is taken from the
table, else as stage 01 records it: x_mm 0 for arcs, and for lines theta_deg the viewing angle of the first stop
(the line's offset from the model view, IV-D), 0 without poses. A
stop's mean position must increase strictly with its index. Without T_cam1_cam0 in dataset.yaml the model pair's
relative pose is T_cam1_ref inv(T_cam0_ref). ``T_base_cam`` (in both tables or in neither): the camera's pose as
the robot reported it, 16 row-major numbers mapping camera points into a frame fixed to the robot's base (mm; its
flange pose times the hand-eye calibration); with a static target it observes each estimate's error
(localization/kinematic_consistency.py).

Ground truth: ``board`` (IV-C): the ArUco board is detected in every image and is the truth; it must be detected in
model image 0, which places the target model in the board frame. ``poses``: the tables' T_cam_ref are the truth
(an external tracker), and model image 0's pose places the target model in the reference frame.

Modules:

    reader.py       read and check a folder, every problem by file and field
    geometry.py     theta, x and the model pair's relative pose from the poses
    model_pair.py   how well the model pair can triangulate the target (its depth error), before any run
    materialize.py  a recorded folder into stage 02's layout, atomically
    export.py       stage-01 datasets to this format
    rosbag.py       a ROS bag (images, camera_info, poses) into a recorded folder
    __main__.py     ``python -m poseintegrity.recorded``: validate, export, import a bag
"""
