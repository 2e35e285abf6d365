"""Helpers of the recorded-format tests and benchmark: run the command line in-process, a bag-stops table of a
folder's images, and write ROS 1 / ROS 2 bags with rosbags' own writers from image arrays or encoded files."""

from __future__ import annotations

import contextlib
import csv
import io
from pathlib import Path

import numpy as np

from poseintegrity.lens import Camera


def run(argv: list[str]) -> tuple[int, str, str]:
    """(exit status, stdout, stderr) of ``python -m poseintegrity.recorded argv``, run in this process."""
    from poseintegrity.recorded.__main__ import main

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            main(argv)
            status = 0
        except SystemExit as exit_:
            status = exit_.code
    return status, out.getvalue(), err.getvalue()


def bag_inputs(folder: Path, tmp_path: Path) -> tuple[list[Path], Path]:
    """The exported dataset's image files in bag order (model pair first) and the bag-stops table naming them."""
    with open(folder / "model.csv") as table:
        model = list(csv.DictReader(table))
    with open(folder / "stops.csv") as table:
        stops = list(csv.DictReader(table))
    files = [folder / row["file"] for row in model] + [folder / row["file"] for row in stops]
    path = tmp_path / "bag_stops.csv"
    with open(path, "w", newline="") as table:
        writer = csv.writer(table)
        writer.writerow(["index", "stop", "theta_deg", "x_mm", "T_cam_ref"])
        for k, row in enumerate(model):
            writer.writerow([k, f"model{k}", "", "", row["T_cam_ref"]])
        for k, row in enumerate(stops, start=len(model)):
            writer.writerow([k, row["stop"], row["theta_deg"], row["x_mm"], row["T_cam_ref"]])
    return files, path


def write_bag(path: Path, ros: int, images: list, camera: Camera, *, image_topic: str = "/camera/image",
              info_topic: str = "/camera/camera_info", encodings: list[str] | None = None,
              projection: np.ndarray | None = None, with_info: bool = True) -> Path:
    """A bag at ``path`` (ROS ``ros`` 1 or 2) with one CameraInfo of ``camera`` (P: ``projection``, default [K|0];
    none with ``with_info`` False, the topic then holds no message) and one message per image at 10 Hz: ``images``
    are encoded files (bytes: CompressedImage, format after their signature) or arrays (Image, encoded as
    ``encodings[k]``: mono8, mono16, bgr8 or rgb8, the array already in that layout)."""
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS1_NOETIC if ros == 1 else Stores.ROS2_HUMBLE)
    T = store.types
    header = (lambda ns: T["std_msgs/msg/Header"](seq=0, stamp=_time(T, ns), frame_id="camera")) if ros == 1 else \
        (lambda ns: T["std_msgs/msg/Header"](stamp=_time(T, ns), frame_id="camera"))
    roi = T["sensor_msgs/msg/RegionOfInterest"](x_offset=0, y_offset=0, height=0, width=0, do_rectify=False)
    K = np.asarray(camera.K, np.float64).ravel()
    matrices = dict(D=np.asarray(camera.dist, np.float64), K=K, R=np.eye(3).ravel(),
                    P=(np.hstack([camera.K, np.zeros((3, 1))]) if projection is None else projection).ravel())
    info = T["sensor_msgs/msg/CameraInfo"](
        header=header(0), height=camera.height, width=camera.width,
        distortion_model="plumb_bob" if len(camera.dist) == 5 else "rational_polynomial",
        **{(key if ros == 1 else key.lower()): value for key, value in matrices.items()},
        binning_x=0, binning_y=0, roi=roi)
    serialize = store.serialize_ros1 if ros == 1 else store.serialize_cdr
    if ros == 1:
        from rosbags.rosbag1 import Writer

        writer = Writer(path)
    else:
        from rosbags.rosbag2 import Writer

        writer = Writer(path, version=9)
    with writer:
        compressed = isinstance(images[0], bytes)
        image_type = "sensor_msgs/msg/CompressedImage" if compressed else "sensor_msgs/msg/Image"
        info_connection = writer.add_connection(info_topic, "sensor_msgs/msg/CameraInfo", typestore=store)
        image_connection = writer.add_connection(image_topic, image_type, typestore=store)
        if with_info:
            writer.write(info_connection, 1, serialize(info, "sensor_msgs/msg/CameraInfo"))
        for k, image in enumerate(images):
            ns = 100_000_000 * (k + 1)
            if compressed:
                kind = "png" if image.startswith(b"\x89PNG") else "jpeg"
                message = T[image_type](header=header(ns), format=kind, data=np.frombuffer(image, np.uint8))
            else:
                encoding = encodings[k]
                data = np.ascontiguousarray(image)
                message = T[image_type](header=header(ns), height=data.shape[0], width=data.shape[1],
                                        encoding=encoding, is_bigendian=0, step=data.strides[0],
                                        data=data.view(np.uint8).ravel())
            writer.write(image_connection, ns, serialize(message, image_type))
    return path


def _time(T, ns: int):
    name = "builtin_interfaces/msg/Time"
    return T[name](sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)


def assert_rows_identical(original, again) -> None:
    """Two artifact tables equal value for value: pandas compares the columns exactly, the pose lists (whose NaN
    of a failed frame no list equality accepts) bit for bit as arrays, NaN where NaN."""
    import pandas as pd

    poses = "T_cam_board_est"
    pd.testing.assert_frame_equal(original.drop(columns=poses), again.drop(columns=poses), check_exact=True)
    a, b = np.stack(original[poses].to_numpy()), np.stack(again[poses].to_numpy())
    assert a.dtype == b.dtype and np.array_equal(a.view(np.uint64), b.view(np.uint64))
