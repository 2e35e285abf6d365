"""import-rosbag against bags written by rosbags' own writers from exported stage-01 images: the images come back
byte for byte (CompressedImage) or pixel for pixel (Image, in every supported encoding), camera.yaml holds the
CameraInfo's camera, the folder passes validate; a bag without the named topic is refused naming bag and topic."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from poseintegrity.lens import read_camera_yaml
from poseintegrity.recorded.reader import RecordedFormatError, read_image, read_recorded
from poseintegrity.recorded.rosbag import import_rosbag
from recorded_tools import bag_inputs, run, write_bag


@pytest.mark.parametrize("ros", [1, 2])
def test_compressed_images_come_back_byte_for_byte(exported, tmp_path, ros):
    folder = exported / "arc_r"
    files, stops = bag_inputs(folder, tmp_path)
    camera = read_camera_yaml(folder / "camera.yaml")
    bag = write_bag(tmp_path / ("run.bag" if ros == 1 else "run"), ros, [f.read_bytes() for f in files], camera)
    status, out, err = run(["import-rosbag", str(bag), "--image-topic", "/camera/image", "--info-topic",
                            "/camera/camera_info", "--stops", str(stops), "--out", str(tmp_path / "arc_r"),
                            "--trajectory", "arc", "--board", str(folder / "board.yaml")])
    assert status == 0, err
    recorded = read_recorded(tmp_path / "arc_r")  # passes every check
    imported = [tmp_path / "arc_r" / f for f in recorded.model_images] + \
               [tmp_path / "arc_r" / frame.file for frame in recorded.frames]
    assert [p.read_bytes() for p in imported] == [f.read_bytes() for f in files]
    assert np.array_equal(recorded.camera.K, camera.K) and np.array_equal(recorded.camera.dist, camera.dist)
    original = read_recorded(folder)
    assert [(f.stop, f.image, f.theta_deg) for f in recorded.frames] == \
           [(f.stop, f.image, f.theta_deg) for f in original.frames]
    assert np.array_equal(recorded.T_cam1_cam0, original.T_cam1_cam0)  # from the model poses, as the robot's


@pytest.mark.parametrize("ros", [1, 2])
def test_raw_images_in_every_encoding_give_the_same_gray_pixels(exported, tmp_path, ros):
    """mono8, bgr8 and rgb8 (equal channels) and mono16 (v * 257): the imported files read as the original 8-bit
    gray pixels."""
    folder = exported / "line_r"
    files, stops = bag_inputs(folder, tmp_path)
    grays = [cv2.imread(str(f), cv2.IMREAD_UNCHANGED) for f in files]
    encodings = ["mono8", "bgr8", "rgb8", "mono16"]
    arrays = [g if e == "mono8" else g.astype(np.uint16) * 257 if e == "mono16" else np.dstack([g, g, g])
              for g, e in zip(grays, encodings)]
    bag = write_bag(tmp_path / ("raw.bag" if ros == 1 else "raw"), ros, arrays, read_camera_yaml(folder / "camera.yaml"), encodings=encodings)
    import_rosbag(bag, "/camera/image", "/camera/camera_info", stops, tmp_path / "line_r", trajectory="line")
    recorded = read_recorded(tmp_path / "line_r")
    assert recorded.ground_truth == "poses"
    imported = [tmp_path / "line_r" / f for f in recorded.model_images] + \
               [tmp_path / "line_r" / frame.file for frame in recorded.frames]
    for path, gray in zip(imported, grays):
        assert np.array_equal(read_image(path)[0], gray)
    assert cv2.imread(str(imported[3]), cv2.IMREAD_UNCHANGED).dtype == np.uint16  # stored as recorded


def test_a_bag_without_the_topic_names_bag_topic_and_the_topics_it_has(exported, tmp_path):
    folder = exported / "line_r"
    files, stops = bag_inputs(folder, tmp_path)
    bag = write_bag(tmp_path / "run", 2, [f.read_bytes() for f in files], read_camera_yaml(folder / "camera.yaml"))
    with pytest.raises(RecordedFormatError) as info:
        import_rosbag(bag, "/cam/image_raw", "/camera/camera_info", stops, tmp_path / "out", trajectory="line")
    message = str(info.value)
    assert str(bag) in message and "no topic '/cam/image_raw'" in message
    assert "/camera/image (sensor_msgs/msg/CompressedImage)" in message and "/camera/camera_info" in message
    status, _, err = run(["import-rosbag", str(bag), "--image-topic", "/cam/image_raw", "--info-topic",
                          "/camera/camera_info", "--stops", str(stops), "--out", str(tmp_path / "out"),
                          "--trajectory", "line"])
    assert status == 2 and len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert not (tmp_path / "out").exists()


def test_an_index_the_topic_does_not_have_and_a_damaged_bag(exported, tmp_path):
    folder = exported / "line_r"
    files, stops = bag_inputs(folder, tmp_path)
    bag = write_bag(tmp_path / "run", 2, [f.read_bytes() for f in files], read_camera_yaml(folder / "camera.yaml"))
    stops.write_text(stops.read_text().replace("\n3,", "\n7,"))
    with pytest.raises(RecordedFormatError, match=r"bag_stops.csv, line 5: field index: message 7 is not on topic"):
        import_rosbag(bag, "/camera/image", "/camera/camera_info", stops, tmp_path / "out", trajectory="line")
    stops.write_text(stops.read_text().replace("\n7,", "\n2,"))
    with pytest.raises(RecordedFormatError, match=r"bag_stops.csv, line 5: field index: message 2 is named on line 4"):
        import_rosbag(bag, "/camera/image", "/camera/camera_info", stops, tmp_path / "out", trajectory="line")
    _, stops = bag_inputs(folder, tmp_path)  # a good table again
    damaged = tmp_path / "damaged.bag"
    damaged.write_bytes(b"#ROSBAG V2.0\n" + bytes(64))
    with pytest.raises(RecordedFormatError, match="damaged.bag: cannot read the bag"):
        import_rosbag(damaged, "/camera/image", "/camera/camera_info", stops, tmp_path / "out", trajectory="line")
