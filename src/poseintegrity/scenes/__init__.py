"""Stage 01: the rendered world of Windsor et al. IV-D.

``catalog`` lays out scenes (targets, clutter, ArUco board, table) from meshes (``mesh``) and textures
(``textures``); ``trajectories`` gives the camera poses of the protocol; ``renderer`` turns a scene and a pose
into a noisy 8-bit image; ``dataset`` writes the datasets; ``params`` is the ``generate`` section's schema.
"""
