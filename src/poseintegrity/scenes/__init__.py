"""Stage 01: the rendered world of Windsor et al. IV-D.

``catalog`` lays out scenes (targets, clutter, ArUco board, table) from meshes (``mesh``) and textures
(``textures``); ``trajectories`` gives the camera poses of the protocol; ``renderer`` turns a scene and a pose
into a noisy 8-bit image; ``robot`` (on :mod:`poseintegrity.kinematics`, a UR5e) turns commanded camera poses into
the actual ones of an imperfect arm and ``ringdown`` gives the camera's vibration after a stop; ``dataset`` writes
the datasets. The ``generate`` section's schema is :mod:`poseintegrity.params.generate`.
"""
