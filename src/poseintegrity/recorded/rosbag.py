"""A recorded dataset folder (:mod:`poseintegrity.recorded`) from a ROS 1 or ROS 2 bag, read with ``rosbags``
(pure Python, no ROS installation).

Read from the bag: the image topic (sensor_msgs/Image with encoding mono8, mono16, bgr8 or rgb8, or
sensor_msgs/CompressedImage) and the first message of the camera-info topic (sensor_msgs/CameraInfo -> camera.yaml:
K, distortion_model plumb_bob or rational_polynomial with its D, width, height, and its P and R as they are). Given by the user: a bag-stops
table, CSV with columns ``index`` (the image's message index on the image topic, 0-based in the bag's time order),
``stop`` (an integer >= 0, or ``model0`` / ``model1`` for the model pair) and optionally ``theta_deg``, ``x_mm`` and
``T_cam_ref`` (copied into stops.csv / model.csv as they are); the trajectory; and the board (its board.yaml: board
ground truth) or none (pose ground truth: the table's T_cam_ref are the truth). Messages the table does not name are
not imported.

Images are written as they were recorded: Image messages as PNG (mono8 and bgr8 unchanged, mono16 as 16-bit PNG,
rgb8 reordered to BGR), CompressedImage messages byte for byte (``.png`` or ``.jpg`` after their format). The folder
``out`` must be new or empty (checked before the bag is opened); it is written atomically (a staging folder beside
it, removed on any error) and is not checked here: ``python -m poseintegrity.recorded validate`` checks it.
"""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import yaml

from poseintegrity.atomic_write import check_new_folder, staged
from poseintegrity.errors import PoseIntegrityError, read_text_file
from poseintegrity.lens import DISTORTION_MODELS, Camera, write_camera_yaml
from poseintegrity.recorded.reader import TRAJECTORIES, RecordedFormatError, read_table, write_table

IMAGE_TYPES = ("sensor_msgs/msg/Image", "sensor_msgs/msg/CompressedImage")
INFO_TYPE = "sensor_msgs/msg/CameraInfo"
ENCODINGS = {"mono8": (np.uint8, 1), "mono16": (np.uint16, 1), "bgr8": (np.uint8, 3), "rgb8": (np.uint8, 3)}
MODEL_STOPS = ("model0", "model1")


def _field(message, *names):
    """A message field under its ROS 2 or ROS 1 name (k / K, d / D)."""
    for name in names:
        if hasattr(message, name):
            return getattr(message, name)
    raise AttributeError(names[0])


def image_from_message(message, where: str) -> tuple[bytes, str]:
    """(file bytes, suffix) of one image message: CompressedImage data as it is, Image data encoded as PNG."""
    if hasattr(message, "format"):
        kind = "png" if "png" in message.format.lower() else "jpeg" if "jp" in message.format.lower() else None
        if kind is None:
            raise RecordedFormatError(f"{where}: CompressedImage format {message.format!r} is neither PNG nor JPEG")
        return bytes(message.data), ".png" if kind == "png" else ".jpg"
    if message.encoding not in ENCODINGS:
        raise RecordedFormatError(f"{where}: image encoding {message.encoding!r} is not one of "
                                  f"{', '.join(ENCODINGS)}")
    dtype, channels = ENCODINGS[message.encoding]
    row_bytes = message.width * channels * np.dtype(dtype).itemsize
    data = np.frombuffer(bytes(message.data), np.uint8)
    if message.width < 1 or message.height < 1 or message.step < row_bytes or data.size < message.step * message.height:
        raise RecordedFormatError(f"{where}: image data of {data.size} bytes does not hold {message.height} rows of "
                                  f"{row_bytes} bytes (step {message.step})")
    rows = data[: message.step * message.height].reshape(message.height, message.step)[:, :row_bytes]
    stored = np.dtype(dtype).newbyteorder(">" if message.is_bigendian else "<")
    image = np.frombuffer(rows.tobytes(), stored).astype(dtype).reshape(message.height, message.width, channels)
    image = image[:, :, 0] if channels == 1 else image[:, :, ::-1] if message.encoding == "rgb8" else image
    return cv2.imencode(".png", np.ascontiguousarray(image))[1].tobytes(), ".png"


def info_matrices(message, where: str) -> tuple[np.ndarray, np.ndarray]:
    """(P (3, 4), R (3, 3)) of a CameraInfo message, kept in camera.yaml as the bag has them (the projection of a
    rectified or stereo camera is not [K | 0])."""
    matrices = []
    for names, shape in ((("p", "P"), (3, 4)), (("r", "R"), (3, 3))):
        values = np.asarray(_field(message, *names), dtype=np.float64)
        if values.size != shape[0] * shape[1] or not np.all(np.isfinite(values)):
            raise RecordedFormatError(f"{where}: field {names[1]} must be {shape[0] * shape[1]} finite numbers, got "
                                      f"{values.tolist()}")
        matrices.append(values.reshape(shape))
    return matrices[0], matrices[1]


def camera_from_info(message, where: str) -> Camera:
    """The camera of a CameraInfo message (plumb_bob: 5 coefficients, rational_polynomial: 8)."""
    model = message.distortion_model
    if model not in DISTORTION_MODELS:
        raise RecordedFormatError(f"{where}: field distortion_model {model!r} is neither plumb_bob nor "
                                  f"rational_polynomial")
    dist = np.asarray(_field(message, "d", "D"), dtype=np.float64)
    if len(dist) != DISTORTION_MODELS[model]:
        raise RecordedFormatError(f"{where}: field D holds {len(dist)} coefficients, {model} has "
                                  f"{DISTORTION_MODELS[model]}")
    try:
        return Camera(np.asarray(_field(message, "k", "K"), dtype=np.float64).reshape(3, 3), dist,
                      int(message.width), int(message.height))
    except PoseIntegrityError as error:
        raise RecordedFormatError(f"{where}: {error}") from None


def _bag_stops(path: Path) -> list[tuple[int, int, dict[str, str]]]:
    """(line, message index, row) of the bag-stops table."""
    rows, problems = [], []
    for line, row in read_table(path, ("index", "stop"), ("theta_deg", "x_mm", "T_cam_ref")):
        if not row["index"].isdigit():
            problems.append(f"{path}, line {line}: field index: expected a message index >= 0, got {row['index']!r}")
        elif row["stop"] not in MODEL_STOPS and not row["stop"].isdigit():
            problems.append(f"{path}, line {line}: field stop: expected an integer >= 0, model0 or model1, "
                            f"got {row['stop']!r}")
        else:
            rows.append((line, int(row["index"]), row))
    seen: dict[int, int] = {}
    for line, index, _ in rows:
        if index in seen:
            problems.append(f"{path}, line {line}: field index: message {index} is named on line {seen[index]} too")
        seen.setdefault(index, line)
    for stop in MODEL_STOPS:
        if sum(row["stop"] == stop for _, _, row in rows) != 1:
            problems.append(f"{path}: field stop: exactly one row must be {stop} (the model pair, III-B)")
    if problems:
        raise RecordedFormatError(problems)
    return rows


def import_rosbag(bag: str | Path, image_topic: str, info_topic: str, stops: str | Path, out: str | Path, *,
                  trajectory: str, board: str | Path | None = None, world: str = "recorded") -> Path:
    """The recorded dataset folder ``out`` built from ``bag`` (module docstring); returns ``out``.

    :class:`~poseintegrity.recorded.reader.RecordedFormatError` naming the bag and topic when the bag cannot be read,
    lacks a topic (listing the topics it has) or holds a message that cannot be converted, and naming the table and
    line for a bad bag-stops table or a message index the topic does not have.
    """
    from rosbags.highlevel import AnyReader, AnyReaderError
    from rosbags.rosbag1 import ReaderError as Ros1ReaderError
    from rosbags.rosbag2 import ReaderError as Ros2ReaderError
    from rosbags.serde import SerdeError
    from rosbags.typesys import TypesysError

    bag, stops, out = Path(bag), Path(stops), check_new_folder(out)  # before any work: nothing of the user's replaced
    if trajectory not in TRAJECTORIES:
        raise RecordedFormatError(f"trajectory: expected one of {', '.join(TRAJECTORIES)}, got {trajectory!r}")
    rows = _bag_stops(stops)
    board_text = read_text_file(Path(board), RecordedFormatError, "board file") if board else None
    wanted = {index: (line, row) for line, index, row in rows}
    try:
        with AnyReader([bag]) as reader:
            topics = {connection.topic: connection.msgtype for connection in reader.connections}
            for topic, types in ((image_topic, IMAGE_TYPES), (info_topic, (INFO_TYPE,))):
                if topic not in topics:
                    raise RecordedFormatError(f"{bag}: no topic {topic!r}; the bag has "
                                              f"{', '.join(f'{t} ({m})' for t, m in sorted(topics.items()))}")
                if topics[topic] not in types:
                    raise RecordedFormatError(f"{bag}: topic {topic!r} carries {topics[topic]}, expected "
                                              f"{' or '.join(types)}")
            info = next(reader.messages([c for c in reader.connections if c.topic == info_topic]), None)
            if info is None:
                raise RecordedFormatError(f"{bag}: topic {info_topic!r} holds no message (a CameraInfo is needed for "
                                          f"camera.yaml)")
            message = reader.deserialize(info[2], info[0].msgtype)
            camera = camera_from_info(message, f"{bag}, topic {info_topic}")
            projection, rectification = info_matrices(message, f"{bag}, topic {info_topic}")
            images, count = {}, 0
            for count, (connection, _, raw) in enumerate(
                    reader.messages([c for c in reader.connections if c.topic == image_topic]), start=1):
                if count - 1 in wanted:
                    images[count - 1] = image_from_message(reader.deserialize(raw, connection.msgtype),
                                                           f"{bag}, topic {image_topic}, message {count - 1}")
    except (AnyReaderError, Ros1ReaderError, Ros2ReaderError, SerdeError, TypesysError, OSError,
            UnicodeDecodeError) as error:  # rosbags' ROS 1 reader decodes a non-bag file's first line unguarded
        raise RecordedFormatError(f"{bag}: cannot read the bag ({type(error).__name__}: {error})") from None
    if missing := [f"{stops}, line {line}: field index: message {index} is not on topic {image_topic} (it has "
                   f"{count})" for index, (line, _) in wanted.items() if index not in images]:
        raise RecordedFormatError(missing)

    with staged(out) as tmp:
        (tmp / "images").mkdir()
        (tmp / "model").mkdir()
        model_rows, stop_rows = {}, []
        for line, index, row in rows:
            data, suffix = images[index]
            folder = "model" if row["stop"] in MODEL_STOPS else "images"
            file = f"{folder}/{index:06d}{suffix}"
            (tmp / file).write_bytes(data)
            cells = [row.get(column, "") for column in ("theta_deg", "x_mm", "T_cam_ref")]
            if row["stop"] in MODEL_STOPS:
                model_rows[row["stop"]] = [file, "", cells[2]]
            else:
                stop_rows.append([file, row["stop"], *cells])
        write_table(tmp / "model.csv", ["file", "mask", "T_cam_ref"], [model_rows[stop] for stop in MODEL_STOPS])
        write_table(tmp / "stops.csv", ["file", "stop", "theta_deg", "x_mm", "T_cam_ref"], stop_rows)
        write_camera_yaml(tmp / "camera.yaml", camera, out.name, projection, rectification)
        settings = {"trajectory": trajectory, "ground_truth": "board" if board else "poses", "world": world}
        (tmp / "dataset.yaml").write_text(yaml.safe_dump(settings, sort_keys=False))
        if board_text is not None:
            (tmp / "board.yaml").write_text(board_text)
    return out
