"""Read a recorded dataset folder (format: :mod:`poseintegrity.recorded`) and check every file before any work.

:func:`problems` lists everything wrong, one line each naming the file and field (and line of a table);
:func:`read_recorded` returns the checked :class:`Recorded` or raises :class:`RecordedFormatError` holding those
lines. Checked: dataset.yaml's fields; camera.yaml (:func:`poseintegrity.lens.read_camera_yaml`: positive focal
lengths, a known distortion model, ...); board.yaml (:class:`~poseintegrity.dataset_meta.BoardMeta`);
model.csv and stops.csv (columns, numbers, rigid poses, stops that never go back and whose positions increase);
every image (listed, present, decodable, 8/16-bit mono or colour, of camera.yaml's size; no image left unlisted);
the board detected in model image 0 (IV-C: it places the target model in the board frame).
"""

from __future__ import annotations

import csv
import io
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import yaml
from pydantic import ValidationError

from poseintegrity.boards import board_description
from poseintegrity.dataset_meta import BoardMeta, pose_problem
from poseintegrity.errors import PoseIntegrityError, read_text_file
from poseintegrity.grayscale import as_gray8
from poseintegrity.lens import Camera, read_camera_yaml
from poseintegrity.localization.ground_truth import board_pose
from poseintegrity.params.protocol import ProtocolParams
from poseintegrity.recorded.geometry import camera_centre, distance_mm, relative_pose, viewing_angle_deg

IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".tif", ".tiff")
RANGE_KEYS = {"arc": ("theta_deg", "protocol.arc_span_deg", "deg"),
              "line": ("x_mm", "protocol.line_length_mm", "mm")}  # position column, range-end key, unit
TRAJECTORIES = ("arc", "line")
GROUND_TRUTHS = ("board", "poses")
DEFAULT_WORLD = "recorded"


class RecordedFormatError(PoseIntegrityError):
    """A recorded dataset folder with problems; ``problems``: one line per problem, naming file and field."""

    def __init__(self, problems: list[str] | str) -> None:
        self.problems = [problems] if isinstance(problems, str) else list(problems)
        super().__init__("\n".join(self.problems))


@dataclass(frozen=True)
class Frame:
    """One row of stops.csv, resolved: file relative to the folder, stop, image (order within the stop),
    theta_deg, x_mm, T_cam_ref (4, 4) mm or None, T_base_cam (4, 4) mm: the camera's pose as the robot reported it,
    or None."""

    file: str
    stop: int
    image: int
    theta_deg: float
    x_mm: float
    T_cam_ref: np.ndarray | None
    T_base_cam: np.ndarray | None = None


@dataclass(frozen=True)
class Recorded:
    """A checked recorded dataset. model_images / model_masks: files relative to the folder (mask None: the whole
    image); T_cam1_cam0 (4, 4) mm; T_cam0_ref: model image 0's pose (None without poses); board: board.yaml as a
    dict (None with ground_truth poses); model_T_base_cam: the model images' camera poses as the robot reported them
    ((4, 4) mm each; None without the robot's poses)."""

    folder: Path
    name: str
    world: str
    trajectory: str
    ground_truth: str
    camera: Camera
    board: dict[str, Any] | None
    model_images: tuple[str, str]
    model_masks: tuple[str | None, str | None]
    T_cam1_cam0: np.ndarray
    T_cam0_ref: np.ndarray | None
    frames: tuple[Frame, ...]
    model_T_base_cam: tuple[np.ndarray, np.ndarray] | None = None


def read_image(path: Path) -> tuple[np.ndarray, bool]:
    """(image, converted): the image file as the pipeline reads it, (h, w) uint8, and whether it had to be converted
    (colour -> gray by OpenCV's weights, 16 bit -> its high byte: :func:`poseintegrity.grayscale.as_gray8`);
    :class:`RecordedFormatError` naming the file when it is empty, damaged or of another kind."""
    try:
        data = path.read_bytes()
    except OSError as error:
        raise RecordedFormatError([f"{path}: cannot read the image ({error.strerror})"]) from None
    if not data:
        raise RecordedFormatError([f"{path}: the image file is empty (0 bytes)"])
    image = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_UNCHANGED)
    if image is None:
        raise RecordedFormatError([f"{path}: not a readable PNG, JPEG or TIFF image (damaged?)"])
    try:
        converted = image.dtype != np.uint8 or image.ndim != 2
        return (as_gray8(str(path), image) if converted else image), converted
    except PoseIntegrityError as error:
        raise RecordedFormatError([f"{path}: {error}"]) from None


class _Problems:
    """Collects problem lines; ``check`` runs a reader and keeps its error as a line."""

    def __init__(self) -> None:
        self.lines: list[str] = []

    def add(self, line: str) -> None:
        self.lines.append(line)

    def check(self, function, *args):
        try:
            return function(*args)
        except RecordedFormatError as error:
            self.lines.extend(error.problems)
        except PoseIntegrityError as error:
            self.lines.append(str(error))
        return None


def _yaml(path: Path) -> dict[str, Any]:
    text = read_text_file(path, RecordedFormatError, "YAML file")
    try:
        content = yaml.safe_load(text)
    except yaml.YAMLError as error:
        raise RecordedFormatError([f"{path}: not valid YAML ({str(error).splitlines()[0]})"]) from None
    if not isinstance(content, dict):
        raise RecordedFormatError([f"{path}: expected a mapping of fields, got {type(content).__name__}"])
    return content


def _pose(text: str, where: str) -> np.ndarray:
    try:
        values = [float(value) for value in text.split()]
    except ValueError:
        raise RecordedFormatError([f"{where}: expected 16 numbers separated by spaces, got {text!r:.60}"]) from None
    problem = pose_problem(values) if len(values) == 16 else f"is not 16 numbers (got {len(values)})"
    if problem:
        raise RecordedFormatError([f"{where}: the pose {problem}"])
    return np.asarray(values, dtype=np.float64).reshape(4, 4)


def _settings(path: Path, problems: _Problems) -> dict[str, Any] | None:
    content = problems.check(_yaml, path)
    if content is None:
        return None
    ok = True
    for key, allowed in (("trajectory", TRAJECTORIES), ("ground_truth", GROUND_TRUTHS)):
        if content.get(key) not in allowed:
            problems.add(f"{path}: field {key} must be one of {', '.join(allowed)}, got {content.get(key)!r}")
            ok = False
    world = content.get("world", DEFAULT_WORLD)
    if not isinstance(world, str) or not world:
        problems.add(f"{path}: field world must be a non-empty name, got {world!r}")
        ok = False
    if unknown := sorted(set(content) - {"trajectory", "ground_truth", "world", "T_cam1_cam0"}):
        problems.add(f"{path}: unknown field(s) {', '.join(map(str, unknown))}")
        ok = False
    T = content.get("T_cam1_cam0")
    if T is not None:
        rows = isinstance(T, list) and all(isinstance(row, list) for row in T)  # 4 rows of 4, or 16 numbers
        flat = [value for row in T for value in row] if rows else T
        if not isinstance(flat, list) or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in flat):
            problems.add(f"{path}: field T_cam1_cam0 must be 16 numbers (row-major), got {T!r:.60}")
            ok = False
        elif problem := pose_problem(flat):
            problems.add(f"{path}: field T_cam1_cam0 {problem}")
            ok = False
    return {"world": world, **content} if ok else None


def _board(path: Path, problems: _Problems) -> dict[str, Any] | None:
    content = problems.check(_yaml, path)
    if content is None:
        return None
    try:
        return BoardMeta.model_validate(content).model_dump(exclude_none=True)
    except ValidationError as error:
        for item in error.errors():
            field = ".".join(map(str, item["loc"])) or "board"
            problems.add(f"{path}: field {field}: {item['msg']}")
    return None


def read_table(path: Path, required: tuple[str, ...], optional: tuple[str, ...]) -> list[tuple[int, dict[str, str]]]:
    """(line number, row) of a CSV table with a header; its columns checked."""
    text = read_text_file(path, RecordedFormatError, "table")
    reader = csv.DictReader(io.StringIO(text))
    columns = reader.fieldnames or []
    lines = []
    if missing := [c for c in required if c not in columns]:
        lines.append(f"{path}: missing column(s) {', '.join(missing)} (header: {', '.join(columns)})")
    if unknown := [c for c in columns if c not in required + optional]:
        lines.append(f"{path}: unknown column(s) {', '.join(unknown)}; known: {', '.join(required + optional)}")
    if lines:
        raise RecordedFormatError(lines)
    rows = [(reader.line_num, row) for row in reader]
    if not rows:
        raise RecordedFormatError([f"{path}: no rows"])
    if extra := [f"{path}, line {line}: {len(row[None])} cell(s) more than the header's {len(columns)} columns"
                 for line, row in rows if None in row]:  # csv.DictReader files surplus cells under None
        raise RecordedFormatError(extra)
    return [(line, {key: (value or "").strip() for key, value in row.items()}) for line, row in rows]


def write_table(path: Path, header: list[str], rows: list[list]) -> None:
    """A CSV table as :func:`read_table` reads it: the header, then one line per row."""
    with open(path, "w", newline="") as table:
        writer = csv.writer(table)
        writer.writerow(header)
        writer.writerows(rows)


def _image_problem(folder: Path, relative: str, where: str, camera: Camera | None) -> str | None:
    path = folder / relative
    if Path(relative).is_absolute() or ".." in Path(relative).parts:
        return f"{where}: image path {relative!r} must be relative to the dataset folder, inside it"
    if path.suffix.lower() not in IMAGE_SUFFIXES:
        return f"{where}: image {relative!r} is not a PNG, JPEG or TIFF file (suffix {path.suffix!r})"
    if not path.is_file():
        return f"{where}: image {relative} is missing"
    try:
        image, _ = read_image(path)
    except RecordedFormatError as error:
        return f"{where}: {error.problems[0]}"
    if camera is not None and (image.shape[1], image.shape[0]) != (camera.width, camera.height):
        return (f"{where}: image {relative} is {image.shape[1]} x {image.shape[0]} px, camera.yaml says "
                f"{camera.width} x {camera.height} px")
    return None


def _poses(rows: list[tuple[int, dict[str, str]]], path: Path, required: bool, problems: _Problems,
           column: str = "T_cam_ref") -> list | None:
    """Each row's pose in ``column`` (or None for all rows when the column is absent / empty everywhere)."""
    cells = [row.get(column, "") for _, row in rows]
    if not any(cells):
        if required:
            problems.add(f"{path}: column {column} is required with ground_truth: poses")
        return None
    poses = []
    for (line, row), cell in zip(rows, cells):
        if not cell:
            problems.add(f"{path}, line {line}: field {column} is empty (give a pose on every row or on none)")
            poses.append(None)
        else:
            poses.append(problems.check(_pose, cell, f"{path}, line {line}: field {column}"))
    return poses


def _number(cell: str, where: str, problems: _Problems, integer: bool = False) -> float | int | None:
    try:
        value = int(cell) if integer else float(cell)
    except ValueError:
        problems.add(f"{where}: expected {'an integer' if integer else 'a number'}, got {cell!r:.40}")
        return None
    if integer and value < 0 or not integer and not np.isfinite(value):
        problems.add(f"{where}: expected {'an integer >= 0' if integer else 'a finite number'}, got {cell!r:.40}")
        return None
    return value


def range_problems(recorded: Recorded, protocol: ProtocolParams, params_name: str = "params.yaml") -> list[str]:
    """The stops of ``recorded`` outside [0, the protocol's range end] of its trajectory type (``protocol.arc_span_deg``
    or ``protocol.line_length_mm``, where every stage fits the artifact models and searches for theta_p, III-D),
    one line naming the key and the value that would hold them; [] when they all lie inside."""
    column, key, unit = RANGE_KEYS[recorded.trajectory]
    end = protocol.range_end(recorded.trajectory)
    values = np.array([getattr(frame, column) for frame in recorded.frames])
    where = f"{recorded.folder / 'stops.csv'}: field {column}"
    lines = []
    if values.max() > end:
        lines.append(f"{where}: the stops reach {values.max():.6g} {unit}, beyond {key} = {end:g} {unit} "
                     f"({params_name}; the range end of every {recorded.trajectory}): set {key} to at least "
                     f"{values.max():.6g} in the params file of your run")
    if values.min() < 0:
        lines.append(f"{where}: a stop at {values.min():.6g} {unit}: positions start at 0 (the model view for arcs, the "
                     f"line's first position for lines), so {key}'s range 0 .. {end:g} {unit} cannot hold it")
    return lines


def problems(folder: str | Path) -> list[str]:
    """Every problem of the recorded dataset folder, one line each naming the file and field; [] when fine."""
    try:
        read_recorded(folder)
    except RecordedFormatError as error:
        return error.problems
    return []


def read_recorded(folder: str | Path) -> Recorded:
    """The checked recorded dataset in ``folder`` (module docstring); :class:`RecordedFormatError` listing every
    problem otherwise."""
    folder = Path(folder)
    if not folder.is_dir():
        raise RecordedFormatError([f"{folder}: not a folder (expected a recorded dataset folder)"])
    found = _Problems()
    settings = _settings(folder / "dataset.yaml", found)
    camera = found.check(read_camera_yaml, folder / "camera.yaml")
    ground_truth = settings["ground_truth"] if settings else None
    board = _board(folder / "board.yaml", found) if ground_truth == "board" else None
    if ground_truth == "poses" and (folder / "board.yaml").exists():
        found.add(f"{folder / 'board.yaml'}: a board with ground_truth: poses (say ground_truth: board to use it)")

    model_path, stops_path = folder / "model.csv", folder / "stops.csv"
    model_rows = found.check(read_table, model_path, ("file",), ("mask", "T_cam_ref", "T_base_cam")) or []
    if model_rows and len(model_rows) != 2:
        found.add(f"{model_path}: expected 2 rows (the model pair, III-B), got {len(model_rows)}")
    stop_rows = found.check(read_table, stops_path, ("file", "stop"), ("theta_deg", "x_mm", "T_cam_ref", "T_base_cam")
                            ) or []

    listed: set[Path] = set()
    board_image = None
    for line, row in model_rows:
        for column in ("file", "mask"):
            if row.get(column):
                listed.add((folder / row[column]).resolve())
                if problem := _image_problem(folder, row[column], f"{model_path}, line {line}, field {column}", camera):
                    found.add(problem)
                elif column == "file" and line == model_rows[0][0]:
                    board_image = row[column]
            elif column == "file":
                found.add(f"{model_path}, line {line}: field file is empty")
    for line, row in stop_rows:
        if row.get("file"):
            if (folder / row["file"]).resolve() in listed:
                found.add(f"{stops_path}, line {line}: field file: image {row['file']} is listed twice")
            listed.add((folder / row["file"]).resolve())
            if problem := _image_problem(folder, row["file"], f"{stops_path}, line {line}, field file", camera):
                found.add(problem)
        else:
            found.add(f"{stops_path}, line {line}: field file is empty")
    for path in sorted(folder.rglob("*")) if model_rows and stop_rows else ():  # both tables read: all listed
        if path.is_file() and path.suffix.lower() in IMAGE_SUFFIXES and path.resolve() not in listed:
            found.add(f"{path}: extra image, listed in neither stops.csv nor model.csv")

    if board is not None and camera is not None and board_image is not None:  # IV-C: the board anchors M_t
        anchor = board_pose(read_image(folder / board_image)[0], board, camera)
        if anchor.status not in ("ok", "bad_ground_truth"):  # a pose that fails its checks still places M_t
            found.add(f"{folder / 'board.yaml'}: the board ({board_description(board)}) is not found in model image "
                      f"{board_image} ({anchor.status}: {anchor.reason})")

    required = ground_truth == "poses"
    model_poses = _poses(model_rows, model_path, required, found) if model_rows else None
    stop_poses = _poses(stop_rows, stops_path, required, found) if stop_rows else None
    T_cam0_ref = model_poses[0] if model_poses else None
    T_cam1_cam0 = None
    if settings and settings.get("T_cam1_cam0") is not None:
        T_cam1_cam0 = np.asarray(settings["T_cam1_cam0"], dtype=np.float64).reshape(4, 4)
    elif model_poses and len(model_poses) == 2 and all(p is not None for p in model_poses):
        T_cam1_cam0 = relative_pose(model_poses[0], model_poses[1])
    elif settings and model_rows and not model_poses:
        found.add(f"{folder / 'dataset.yaml'}: field T_cam1_cam0 is needed: model.csv gives no poses to compute "
                  f"the model pair's relative pose from")

    model_robot = _poses(model_rows, model_path, False, found, "T_base_cam") if model_rows else None
    stop_robot = _poses(stop_rows, stops_path, False, found, "T_base_cam") if stop_rows else None
    if model_rows and stop_rows and (model_robot is None) != (stop_robot is None):
        found.add(f"{model_path if model_robot is None else stops_path}: column T_base_cam is needed too: the "
                  f"robot's poses go in both tables (model image 0's places the target in the robot's base frame) "
                  f"or in neither")
    frames = _frames(stop_rows, stop_poses, T_cam0_ref, settings, stops_path, found) if settings else ()
    if found.lines:
        raise RecordedFormatError(found.lines)
    if stop_robot is not None:
        frames = tuple(replace(frame, T_base_cam=pose) for frame, pose in zip(frames, stop_robot))
    return Recorded(folder, folder.resolve().name, settings["world"], settings["trajectory"], ground_truth, camera,
                    board, (model_rows[0][1]["file"], model_rows[1][1]["file"]),
                    (model_rows[0][1].get("mask") or None, model_rows[1][1].get("mask") or None), T_cam1_cam0,
                    T_cam0_ref, frames, None if model_robot is None else tuple(model_robot))


def _computed(rows: list[tuple[int, dict[str, str]]], poses: list | None, T_cam0_ref: np.ndarray | None,
              trajectory: str) -> list[dict[str, float]]:
    """Per row, the positions its pose gives ({} without poses). Arcs: theta_i, the rotation angle between the model
    pose and pose i (III-D), and x 0 (stage 01 records none). Lines: x_i, the distance of camera i's centre from the
    trajectory's first position (V-A: the first stop's mean camera centre), and theta the viewing angle of that first
    position (the line's offset from the model view, IV-D), constant along the line."""
    if not poses or T_cam0_ref is None or any(pose is None for pose in poses):
        return [{} for _ in rows]
    stack = np.stack(poses)
    first = np.array([row.get("stop") == rows[0][1].get("stop") for _, row in rows])
    if trajectory == "arc":
        return [{"theta_deg": float(theta), "x_mm": 0.0} for theta in viewing_angle_deg(T_cam0_ref, stack)]
    origin = camera_centre(stack[first]).mean(axis=0)
    offset = float(np.mean(viewing_angle_deg(T_cam0_ref, stack[first])))
    return [{"theta_deg": offset, "x_mm": float(x)} for x in distance_mm(origin, stack)]


def _frames(rows: list[tuple[int, dict[str, str]]], poses: list | None, T_cam0_ref: np.ndarray | None,
            settings: dict[str, Any], path: Path, found: _Problems) -> tuple[Frame, ...]:
    """The stops.csv rows resolved: stop and image indices, theta_deg and x_mm given or computed from the poses
    (:func:`_computed`)."""
    position_column = "theta_deg" if settings["trajectory"] == "arc" else "x_mm"
    computed = _computed(rows, poses, T_cam0_ref, settings["trajectory"])
    frames, previous, counts = [], -1, {}
    for index, (line, row) in enumerate(rows):
        where = f"{path}, line {line}"
        stop = _number(row.get("stop", ""), f"{where}: field stop", found, integer=True)
        values = {}
        for column in ("theta_deg", "x_mm"):
            if row.get(column):
                values[column] = _number(row[column], f"{where}: field {column}", found)
            elif column in computed[index]:
                values[column] = computed[index][column]
            elif column == position_column:
                found.add(f"{where}: field {column} is empty and there is no pose to compute it from")
                values[column] = None
            else:
                values[column] = 0.0  # the position an arc (line) does not vary, neither recorded nor computable
        if stop is None or None in values.values():
            continue
        if stop < previous:
            found.add(f"{where}: field stop: stops not monotonic, stop {stop} after stop {previous} (rows of a stop "
                      f"follow each other, stops in increasing order)")
        previous = max(previous, stop)
        counts[stop] = counts.get(stop, 0) + 1
        frames.append(Frame(row["file"], stop, counts[stop] - 1, values["theta_deg"], values["x_mm"],
                            poses[index] if poses else None))
    means = {stop: np.mean([getattr(f, position_column) for f in frames if f.stop == stop]) for stop in counts}
    ordered = sorted(means)
    for before, after in zip(ordered, ordered[1:]):
        if not means[after] > means[before]:
            found.add(f"{path}: field {position_column}: stops not monotonic, stop {after} at {means[after]:.6g} does "
                      f"not lie beyond stop {before} at {means[before]:.6g}")
    return tuple(frames)
