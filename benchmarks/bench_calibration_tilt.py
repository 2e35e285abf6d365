"""How much the calibration views must tilt for stage 01's calibration to find the camera: the session of
params.yaml (scenes/calibration_views.py) rendered with ``generate.calibration.max_tilt_deg`` swept, then calibrated
as stage 01 does (k3 held at 0), for several seeds (other poses and noise).

Zhang's method (Zhang 2000, section 3.3: "if the plane undergoes a pure translation ... the second homography does
not help"; views of parallel planes are degenerate) takes the focal length from how the views' planes differ in
orientation: with every view facing the camera (max_tilt_deg 0) a larger focal length and a farther board explain
the images equally well, and the estimate drifts without bound while its reprojection RMS stays small. Printed per
tilt: the reprojection RMS, the focal length's error (% of f, the worst over the seeds), the ray error of the
estimate over the image (RMS, px, the worst over the seeds; bench_calibration.py) and whether calibrate refused it.

Usage: .venv/bin/python benchmarks/bench_calibration_tilt.py [--params params.yaml] [--seeds 0 1 2]
                                                            [--tilts 0 1 2 3 5 7.5 10 15 20 40]
"""

from __future__ import annotations

import argparse

import numpy as np

from bench_calibration import ray_errors
from poseintegrity.calibration import CalibrationError
from poseintegrity.config import load_params
from poseintegrity.scenes import calibration_views as views
from poseintegrity.scenes.camera import true_camera


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--params", default="params.yaml")
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2])
    parser.add_argument("--tilts", type=float, nargs="+", default=[0, 1, 2, 3, 5, 7.5, 10, 15, 20, 40])
    args = parser.parse_args()
    base = load_params(args.params).generate.world("main")
    true = true_camera(base.camera)
    w, h = true.width, true.height
    u, v = np.meshgrid(np.arange(0, w, 8, dtype=float), np.arange(0, h, 8, dtype=float))
    grid = np.column_stack([u.ravel(), v.ravel()])
    print(f"{w} x {h} px, f = {true.K[0, 0]:.1f} px, {base.calibration.n_views} views, seeds {args.seeds}")
    print("max_tilt_deg  RMS px (max)  |fx error| % (max)  |fy error| % (max)  ray RMS px (max)  refused")
    for tilt in args.tilts:
        rms, fx, fy, ray, refused = [], [], [], [], []
        for seed in args.seeds:
            params = base.model_copy(update={"seed": seed, "calibration": base.calibration.model_copy(
                update={"max_tilt_deg": tilt, "max_rms_px": 5.0})})
            try:
                session = views.calibration_session(params, "generate.calibration")
            except CalibrationError as error:
                refused.append(str(error)[:60])
                continue
            K = session.calibration.camera.K
            rms.append(session.calibration.rms_px)
            fx.append(abs(K[0, 0] / true.K[0, 0] - 1) * 100)
            fy.append(abs(K[1, 1] / true.K[1, 1] - 1) * 100)
            errors = np.linalg.norm(ray_errors(true, session.calibration.camera, grid), axis=1)
            ray.append(float(np.sqrt(np.mean(errors**2))))
        worst = (lambda values: f"{max(values):10.4f}" if values else f"{'-':>10}")
        print(f"{tilt:12g}  {worst(rms)}    {worst(fx)}          {worst(fy)}          {worst(ray)}       "
              f"{len(refused)}/{len(args.seeds)} {refused[0] if refused else ''}", flush=True)


if __name__ == "__main__":
    main()
