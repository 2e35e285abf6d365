"""The physical world of the experiments: targets, clutter, the ground-truth board and the table (Fig. 3-4).

Targets are the same physical objects in every scene they appear in (their meshes and textures are seeded by name
from ``generate.seed``), arranged differently per scene:

- ``scapula`` / ``scapula_drilled``: the anatomical scapula phantom of bone foam (:mod:`.scapula`, :mod:`.foam`),
  the second pre-drilled in the glenoid; held on a rod so that its glenoid faces the model camera tilted by the
  scene's ``glenoid_tilt_deg`` (a surgeon's camera looks at the glenoid, never quite en face);
- ``block_print`` / ``block_mosaic``: boxes printed on their sides (faint lids), set corner-on to the model camera.

The ground-truth boards lie beside the targets or stand on posts (:mod:`.scene_boards`), each as the lab printed and
measured it (:mod:`.printed_boards`). Clutter mixes printed boxes and cylinders (some printed like the blocks) with
bone-foam offcuts (a block and a shaft of the phantoms' material): real scenes hold look-alikes that make false
matches. World frame: table top z = 0, z up, millimetres.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from scipy.spatial.transform import Rotation

from poseintegrity.params.generate import TEXTURE_NAMES, BoneFoamParams, GenerateParams, SceneSpec
from poseintegrity.params.protocol import ProtocolParams
from poseintegrity.poses import pose_matrix
from poseintegrity.scenes import board_plan, board_stand
from poseintegrity.scenes import mesh as meshes
from poseintegrity.scenes import textures as tex
from poseintegrity.scenes.camera import Intrinsics
from poseintegrity.scenes.printed_boards import measured_board
from poseintegrity.scenes.scapula import scapula_mesh
from poseintegrity.scenes.scene_boards import SceneBoard, board_texture_name, drawings, flat_board, standing_boards
from poseintegrity.seeding import keyed_rng

PRINTED_CLUTTER = ("clutter_a", "clutter_b", "clutter_c", "clutter_print")
BLOCK_SIZE_MM = (72.0, 64.0, 58.0)
STAND_RADIUS_MM = 8.0
PHANTOM_CLEARANCE_MM = 20.0  # lowest point of a held phantom above the table
CLUTTER_MAX_HEIGHT_MM = 160.0  # the tallest clutter object


@lru_cache(maxsize=len(TEXTURE_NAMES))
def procedural_texture(name: str, seed: int) -> np.ndarray:
    """The albedo map of a texture name, the same in every scene and process: drawn once per process (most of a
    scene's layout time went into drawing the same textures again), read-only."""
    texture = _draw_texture(name, keyed_rng(seed, "texture", name))
    texture.flags.writeable = False
    return texture


def _draw_texture(name: str, rng: np.random.Generator) -> np.ndarray:
    if name == "block_print":
        return _faint_lid(tex.collage_texture(rng, (1024, 1536), density=3.0, contrast=0.45, text=True), rng)
    if name == "block_mosaic":
        return _faint_lid(tex.collage_texture(rng, (1024, 1536), density=5.0, contrast=0.35, text=False), rng)
    if name == "table":
        return tex.wood_texture(rng, 2048)
    if name == "clutter_print":  # packaging printed like the target blocks
        return tex.collage_texture(rng, (768, 768), density=3.0, contrast=0.4, text=True)
    return tex.collage_texture(rng, (512, 512), density=0.8, contrast=0.25, text=name == "clutter_a")


def _faint_lid(albedo: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """A box printed on its sides, its lid (the +z face's sixth of the texture, see
    :func:`~poseintegrity.scenes.mesh.box`) printed faintly (30 % contrast) on grey board. A fully printed lid
    seen from above is one plane with many features: arcs over the top then keep 130 inliers while the error
    grows (a 20 mm-baseline model cannot pin the tilt of a small plane); a plain lid starves those arcs within
    10 deg, leaving n_i at its chance floor for the rest of the arc."""
    h, w = albedo.shape
    rows, cols = slice(h // 2, h), slice(w // 3, 2 * w // 3)
    printed = albedo[rows, cols].astype(np.float32) / 255
    lid = 0.62 + 0.3 * (printed - printed.mean()) + 0.02 * tex.fractal_noise(rng, printed.shape, 3, 3)
    out = albedo.copy()
    out[rows, cols] = tex.to_u8(lid)
    return out


def foam_material(bone_foam: BoneFoamParams) -> meshes.Material:
    """The reflectance of ``generate.bone_foam``: its mean albedo, under its relief (:mod:`.foam`), and its lobe."""
    return meshes.Material(specular=bone_foam.specular, shininess=bone_foam.shininess, foam_albedo=bone_foam.albedo)


def target_mesh(name: str, params: "GenerateParams") -> meshes.Mesh:
    """A target in its own frame: +z the face shown to the model camera (the glenoid for the scapula phantoms,
    whose origin is the glenoid centre; the lid for a box, whose origin is its centre)."""
    if name.startswith("scapula"):
        bone = scapula_mesh(params.scapula, drilled=name == "scapula_drilled")
        return meshes.from_trimesh(bone, foam_material(params.bone_foam))
    return meshes.box(BLOCK_SIZE_MM, name, material=meshes.Material(specular=0.08, shininess=30.0))


@dataclass
class Scene:
    """A laid-out scene: placed meshes, which of them are targets, the boards, the model-view direction (the
    textures of its meshes: :func:`scene_textures`).

    T_world_target is the frame of the first target; ``boards`` the ground-truth boards (one, or two where one
    cannot serve every trajectory), ``board_of`` per trajectory of the session (``arcs.azimuths_deg`` or
    ``lines.offsets_deg``, in order) the index of the board that is its ground truth (:meth:`board_for`); ``aim``
    is the point the camera looks at and the arcs turn about (the glenoid centre of a single scapula: the paper's
    robot keeps its guide wire in the drill hole); ``plan``: the boards' plan (standing boards), which rebuilds the
    scene without planning again.
    """

    name: str
    placed: list[tuple[str, meshes.Mesh]]
    target_objects: tuple[str, ...]
    T_world_target: np.ndarray
    boards: tuple[SceneBoard, ...]
    board_of: tuple[int, ...]
    aim: np.ndarray
    view_dir: np.ndarray
    light_dir: np.ndarray
    plan: board_plan.BoardPlan | None = None

    def board_for(self, trajectory: int) -> SceneBoard:
        """The board of the session's trajectory ``trajectory`` (its index in ``arcs.azimuths_deg`` or
        ``lines.offsets_deg``): the dataset's ground truth and model origin."""
        return self.boards[self.board_of[trajectory]]


def _model_view_frame(view_dir: np.ndarray) -> np.ndarray:
    """(3, 3) columns: the model camera's x (right), y (down) and the direction towards it, world frame."""
    x = np.cross(-view_dir, [0.0, 0.0, 1.0])
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(-view_dir, x), view_dir])


def _held_phantom(name: str, params: "GenerateParams", spec: "SceneSpec", view_dir: np.ndarray,
                  side: np.ndarray) -> tuple[np.ndarray, list[tuple[str, meshes.Mesh]]]:
    """T_world_phantom and the placed phantom + its stand: the glenoid normal is the direction towards the model
    camera turned by ``spec.glenoid_tilt_deg`` (about the camera's x, then y axis), the inferior angle as low as
    that allows (a scapula held upright), the lowest point PHANTOM_CLEARANCE_MM above the table."""
    C = _model_view_frame(view_dir)
    tilt_x, tilt_y = np.radians(spec.glenoid_tilt_deg)
    normal = Rotation.from_rotvec(tilt_y * C[:, 1]).apply(Rotation.from_rotvec(tilt_x * C[:, 0]).apply(view_dir))
    inferior = np.array([0.0, 0.0, -1.0]) + normal[2] * normal  # world down, orthogonal to the normal
    inferior /= np.linalg.norm(inferior)
    R = np.column_stack([inferior, np.cross(normal, inferior), normal])
    phantom = target_mesh(name, params)
    lowest = float((phantom.vertices @ R.T)[:, 2].min())
    T = pose_matrix(R, side + np.array([0.0, 0.0, PHANTOM_CLEARANCE_MM - lowest]))
    placed = phantom.transformed(T)
    # the rod holding it: from the table up to its lowest vertex
    foot = placed.vertices[placed.vertices[:, 2].argmin()]
    stand = meshes.cylinder(STAND_RADIUS_MM, foot[2] + 2.0, "clutter_c").transformed(pose_matrix(np.eye(3), [*foot[:2], 0]))
    return T, [(name, placed), (f"{name}_stand", stand)]


@dataclass(frozen=True)
class Arrangement:
    """A scene's targets on the table, before its boards and clutter: the scene's generator (``rng``, drawn as far as
    the targets; the boards and the clutter draw on from it), the model camera's direction around the target
    (``yaw``, rad) and towards it (``view_dir`` (3,)), the table and targets placed (with a scapula's stand), each
    target's T_world_target (4, 4) and the point the camera looks at (``aim`` (3,), mm: the targets' mean)."""

    rng: np.random.Generator
    yaw: float
    view_dir: np.ndarray
    placed: tuple[tuple[str, meshes.Mesh], ...]
    target_poses: list[np.ndarray]
    aim: np.ndarray


def arrange(spec: "SceneSpec", index: int, params: "GenerateParams") -> Arrangement:
    """The targets of scene ``spec`` (index = its position in params) placed on the table (:class:`Arrangement`):
    where the camera will look and from where, before any board is planned (``build_scene`` goes on from here; a
    world's population draw checks from it that the robot reaches the scene, population/draw.py)."""
    rng = keyed_rng(params.seed, "scene", index)
    yaw = np.deg2rad(rng.uniform(-20, 20))  # direction of the model camera around the target
    elev = np.deg2rad(spec.elevation_deg)
    view_dir = np.array([np.sin(yaw) * np.cos(elev), -np.cos(yaw) * np.cos(elev), np.sin(elev)])
    placed: list[tuple[str, meshes.Mesh]] = [
        ("table", meshes.plane(1400.0, 1400.0, 56, 56, "table", material=meshes.Material(0.03, 8.0)))]
    target_poses = []
    for k, name in enumerate(spec.targets):
        side = np.array([np.cos(yaw), np.sin(yaw), 0.0]) * 130.0 * k  # further targets stand beside the first
        if name.startswith("scapula"):
            T, objects = _held_phantom(name, params, spec, view_dir, side)
            placed += objects
        else:
            # a corner towards the model camera, so that two printed sides are in view (a 3D point set)
            R = Rotation.from_euler("z", yaw + np.pi / 4 + rng.uniform(-0.25, 0.25)).as_matrix()
            T = pose_matrix(R, side + np.array([0.0, 0.0, BLOCK_SIZE_MM[2] / 2]))
            placed.append((name, target_mesh(name, params).transformed(T)))
        target_poses.append(T)
    aim = np.mean([T[:3, 3] for T in target_poses], axis=0)
    return Arrangement(rng, float(yaw), view_dir, tuple(placed), target_poses, aim)


def build_scene(spec: "SceneSpec", index: int, params: "GenerateParams", protocol: "ProtocolParams",
                session: str = "arc", plan: board_plan.BoardPlan | None = None) -> Scene:
    """Lay out scene ``spec`` (index = its position in params, seeds the arrangement with ``params.seed``) for one
    session: its arcs (``"arc"``) or, on the lines' scene, its lines (``"line"``). Each session has its own model pair
    (IV-D), and the lab stands the ground-truth boards where that session's trajectories (``protocol``) keep them in
    view; targets, their stands and the table are the same in both, the clutter keeps clear of the boards' sight lines.
    A board that fits nowhere raises :class:`~.board_stand.PlacementError`; ``plan``: the boards' plan found by an
    earlier call for the same session (the search is skipped: workers rebuild a scene the main process laid out)."""
    arranged = arrange(spec, index, params)
    rng, yaw, view_dir, placed, target_poses, aim = (arranged.rng, arranged.yaw, arranged.view_dir,
                                                     list(arranged.placed), arranged.target_poses, arranged.aim)
    board_yaw = yaw + np.pi + rng.uniform(-0.3, 0.3)  # drawn for either placement: the clutter after it lies alike
    n_trajectories = len(params.arcs.azimuths_deg) if session == "arc" else len(params.lines.offsets_deg)
    if params.board.placement == "flat":
        drawing = params.board.drawing()
        T_world_board, board_objects, board_centre = flat_board(params, drawing, board_yaw, target_poses[0], yaw, aim,
                                                                view_dir)
        boards, board_of, sight = (SceneBoard(drawing, measured_board(params, drawing), T_world_board),), None, None
        feet = [board_centre]
    else:
        plan, board_objects, sight = standing_boards(params, protocol, spec, session, placed, aim, view_dir, plan)
        boards = tuple(SceneBoard(drawing, measured_board(params, drawing), b.placement.T_world_board, b.placement,
                                  b.sigma_t_mm) for b, drawing in zip(plan.boards, drawings(params, plan)))
        board_of, feet = plan.board_of, [b.placement.post_foot[:2] for b in plan.boards]
    placed += board_objects
    placed += _clutter(spec, params, rng, aim, view_dir[:2] / np.linalg.norm(view_dir[:2]), feet, sight)

    light_dir = np.array([rng.uniform(-0.5, 0.5), rng.uniform(-0.5, 0.3), 1.0])
    return Scene(spec.name, placed, tuple(spec.targets), target_poses[0], boards, board_of or (0,) * n_trajectories,
                 aim, view_dir, light_dir, plan if params.board.placement != "flat" else None)


def scene_textures(scene: Scene, params: "GenerateParams") -> dict[str, np.ndarray]:
    """The albedo map of every texture the scene's meshes use: an image file of ``generate.textures`` or the
    procedural texture of that name, and the printed ground-truth boards."""
    used = {m.texture for _, m in scene.placed if m.texture is not None}
    boards = {board_texture_name(k): b.drawing for k, b in enumerate(scene.boards)}
    textures = {name: (tex.load_texture(params.textures[name]) if name in params.textures
                       else procedural_texture(name, params.seed)) for name in used if name not in boards}
    textures |= {name: tex.board_texture(drawing, params.board.px_per_mm, params.board.margin_mm)
                 for name, drawing in boards.items()}
    return textures


def _clutter(spec: "SceneSpec", params: "GenerateParams", rng: np.random.Generator, aim: np.ndarray,
             toward_cam: np.ndarray, board_feet: list[np.ndarray],
             sight: tuple[list[np.ndarray], list[np.ndarray]] | None) -> list[tuple[str, meshes.Mesh]]:
    """``spec.n_clutter`` objects around the target, off the line of sight of the model view and off the boards
    (``board_feet``: where each stands on the table, (2,)): printed boxes and cylinders, and (one in three) bone-foam
    offcuts, a block or a shaft. ``sight``: the standing boards' paper corners (4, 3 each) and the scene's poses; no
    object (as tall as any can be) may cover a board at any of them."""
    occupied = [(aim[:2], 90.0 + 130.0 * (len(spec.targets) - 1))] + [(foot, 80.0) for foot in board_feet]
    foam = foam_material(params.bone_foam)
    placed, attempts = [], 0
    while len(placed) < spec.n_clutter and attempts < 500:
        attempts += 1
        r, a = rng.uniform(130, 400), rng.uniform(0, 2 * np.pi)
        xy = aim[:2] + r * np.array([np.cos(a), np.sin(a)])
        radius = rng.uniform(20, 50)
        offset = xy - aim[:2]
        if offset @ toward_cam > 0 and abs(toward_cam[0] * offset[1] - toward_cam[1] * offset[0]) < 120:
            continue
        if any(np.linalg.norm(xy - c) < radius + rc for c, rc in occupied):
            continue
        if sight is not None and any(board_stand.covers(xy, radius, CLUTTER_MAX_HEIGHT_MM, paper, sight[1],
                                                        Intrinsics.from_params(params.camera).K)
                                     for paper in sight[0]):
            continue
        occupied.append((xy, radius))
        kind = rng.random()
        if kind < 1 / 3:  # bone foam: a test block or a long-bone-like shaft of the phantoms' material
            if rng.random() < 0.5:
                size = (2 * radius, rng.uniform(0.6, 1.2) * radius, rng.uniform(30, 90))
                obj = meshes.box(size, None, n_sub=8, material=foam)
                T = pose_matrix(Rotation.from_euler("z", rng.uniform(0, np.pi)).as_matrix(), [*xy, size[2] / 2])
            else:
                obj = meshes.cylinder(0.45 * radius, rng.uniform(80, 160), None, n_seg=48, material=foam)
                T = pose_matrix(np.eye(3), [*xy, 0.0])
        elif kind < 2 / 3:
            texture = PRINTED_CLUTTER[rng.integers(len(PRINTED_CLUTTER))]
            size = (2 * radius, rng.uniform(0.5, 1.5) * radius, rng.uniform(25, 140))
            obj = meshes.box(size, texture, n_sub=4)
            T = pose_matrix(Rotation.from_euler("z", rng.uniform(0, np.pi)).as_matrix(), [*xy, size[2] / 2])
        else:
            texture = PRINTED_CLUTTER[rng.integers(len(PRINTED_CLUTTER))]
            obj = meshes.cylinder(0.8 * radius, rng.uniform(40, 160), texture, n_seg=40)
            T = pose_matrix(np.eye(3), [*xy, 0.0])
        placed.append((f"clutter_{len(placed)}", obj.transformed(T)))
    return placed
