"""Our NC driving a plant FMU from an independent exporter, in SI, through ServoDrive FMUs,
with no code between the FMUs (issue 24): the SI PathInterpolator2D and ContourCCC2D, one
ServoDrive per axis, and per axis a slide with viscous and Coulomb friction exported by
pythonfmu (tests/fmpy/helpers/friction_slide.py: force in N, position in m, velocity in
m/s), wired by contour_fmu.loops.wiring.drive_loop_connections in the fmpy master.

The same loop with XYServoPlant configured alike is the reference: the slide carries the
paper's axis reflected to the table (m = J k^2, b = B k^2, Fc = Tc k with k = 2 pi / lead,
so 5922 kg, 4.74e5 N s/m and 628 N for Tc = 1 N m at the motor) and the drive its PI gains
in force units (Kvp_d = CT Kvp k^2, Kvi_d = CT Kvi k^2: the motor current times CT k is the
force at the table). The two loops then differ only in one thing: ServoDrive samples its
inputs once per communication step h and holds its force over the step, where the
plant's drive is continuous. The difference is first order in h (the drive's effort lags
the continuous law by about h/2): halving h halves it, and at h = 0.1 ms it is below 1 um.
What the friction does to each loop (with it less without) is compared on its own, so the
slide's friction is checked, not only the drive's sampling.
"""

import subprocess
import sys

import numpy as np
import pytest

from contour_fmu.engines import native
from contour_fmu.loops import ssp
from contour_fmu.engines.master import Master, Unit, closed_loop
from contour_fmu.loops.wiring import drive_loop_connections, drive_loop_start
from helpers.checkout import REPO

LEAD = 0.01  # m
K = 2.0 * np.pi / LEAD  # motor rad per m
J, B, CT, KVP, KVI = 0.015, 1.2, 0.57, 8.26, 661.0  # the paper's axis (design 4.5)
COULOMB = 1.0  # N m at the motor


@pytest.fixture(scope="module")
def slide_fmu(tmp_path_factory):
    """FrictionSlide.fmu, built by pythonfmu from the test's own source."""
    out = tmp_path_factory.mktemp("pythonfmu")
    script = REPO / "tests" / "fmpy" / "helpers" / "friction_slide.py"
    done = subprocess.run([sys.executable, "-m", "pythonfmu", "build", "-f", str(script), "-d", str(out)],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return str(out / "FrictionSlide.fmu")


def drive_units(fmu_dir, slide, ccc, coulomb=COULOMB, build="fmu-si"):
    """The SI loop's units, in stepping order, with their start values; our FMUs from
    `build` (fmu-si: FMI 2.0, fmu3-si: FMI 3.0)."""
    si = fmu_dir.parent / build
    mechanics = dict(m=J * K**2, b=B * K**2, Fc=coulomb * K)
    drive = dict(Kvp=CT * KVP * K**2, Kvi=CT * KVI * K**2, effortMax=1e9)
    return [
        Unit("controller", str(si / "ContourCCC2D.fmu"), {"ccc.enable": ccc}),
        Unit("drive_x", str(si / "ServoDrive.fmu"), drive),
        Unit("drive_y", str(si / "ServoDrive.fmu"), drive),
        Unit("axis_x", slide, mechanics),
        Unit("axis_y", slide, mechanics),
        Unit("interpolator", str(si / "PathInterpolator2D.fmu"), {"path": "circle"}),
    ]


def drive_loop(fmu_dir, slide, step, ccc, coulomb=COULOMB, stop=2.0, build="fmu-si"):
    """The SI loop: positions in mm at every communication point."""
    units = drive_units(fmu_dir, slide, ccc, coulomb, build)
    with Master(units, drive_loop_connections(), step, stop, initial=drive_loop_start()) as master:
        before, _ = master.run([("axis_x", "x"), ("axis_y", "x")])
    return np.column_stack([before["axis_x.x"], before["axis_y.x"]]) * 1e3


def plant_loop(fmu_dir, step, ccc, coulomb=COULOMB):
    """The mm loop with XYServoPlant and the same friction at the motor."""
    before, _ = closed_loop(fmu_dir, step=step, controller={"ccc.enable": ccc},
                            plant={"x.coulomb": coulomb, "y.coulomb": coulomb})
    return np.column_stack([before["plant.pos.x"], before["plant.pos.y"]])


def contour_error(p):
    """|distance to the circle's centre (-10, 0) - 10| in mm: the true contour error."""
    return np.abs(np.hypot(p[:, 0] + 10.0, p[:, 1]) - 10.0)


def largest_gap(a, b):
    return np.max(np.hypot(*(a - b).T))


def test_the_nc_drives_a_foreign_si_plant_through_servo_drives(fmu_dir, slide_fmu):
    coarse, fine = 2e-4, 1e-4
    runs = {(h, ccc): drive_loop(fmu_dir, slide_fmu, h, ccc) for h in (coarse, fine)
            for ccc in (False, True)}
    without, with_ccc = (contour_error(runs[fine, ccc]).max() for ccc in (False, True))
    print(f"pythonfmu loop, h = 0.1 ms: max contour error {without * 1e3:.2f} um without CCC, "
          f"{with_ccc * 1e3:.2f} um with the fuzzy CCC")
    assert with_ccc < 0.1 * without
    gaps = {}
    for (h, ccc), positions in runs.items():
        gaps[h, ccc] = largest_gap(positions, plant_loop(fmu_dir, h, ccc))
    print("largest gap to the XYServoPlant loop (um):",
          {f"{h * 1e3} ms, CCC {ccc}": round(float(g) * 1e3, 3) for (h, ccc), g in gaps.items()})
    for ccc in (False, True):
        assert gaps[fine, ccc] <= 0.55 * gaps[coarse, ccc], "first order in the step"
        assert gaps[fine, ccc] < 1e-3
    # The slide's friction against the plant's: what friction does to each loop (the run
    # with it less the run without), the sampling's share cancelled. Friction moves the
    # loop by 2.7 um at its reversals; the two agree to a small part of that.
    slide_effect = runs[fine, True] - drive_loop(fmu_dir, slide_fmu, fine, True, coulomb=0.0)
    plant_effect = plant_loop(fmu_dir, fine, True) - plant_loop(fmu_dir, fine, True, coulomb=0.0)
    effect = np.max(np.hypot(*plant_effect.T))
    mismatch = np.max(np.hypot(*(slide_effect - plant_effect).T))
    print(f"friction moves the loop by {effect * 1e3:.3f} um; the two loops' friction effects "
          f"differ by {mismatch * 1e3:.3f} um")
    assert effect > 2e-3
    assert mismatch < 0.05 * effect


def test_the_drive_loop_with_a_pythonfmu_plant_runs_in_contour_cosim_as_in_fmpy(fmu_dir, slide_fmu,
                                                                                cosim, tmp_path):
    """The same loop as an SSP file (contour_fmu.loops.ssp.write_loop) run by the native master,
    with the pythonfmu slides loaded into its process (libpython preloaded): fmpy's
    trajectory bit for bit, and without libpython a refusal that says what to do."""
    step, stop = 2e-4, 0.3
    units = drive_units(fmu_dir, slide_fmu, ccc=True)
    ssd = ssp.write_loop(tmp_path / "drive_loop.ssd", "drive_loop", {u.name: u.path for u in units},
                         [u.name for u in units], drive_loop_connections(), drive_loop_start(),
                         {u.name: u.start_values for u in units}, step=step)
    rows = native.run(ssd, parameter_set="default", stop=stop, record=[("axis_x", "x"), ("axis_y", "x")],
                      env=native.pythonfmu_environment())
    ours = np.column_stack([rows["axis_x.x"], rows["axis_y.x"]])[:-1] * 1e3
    theirs = drive_loop(fmu_dir, slide_fmu, step, True, stop=stop)
    assert len(ours) == len(theirs) == round(stop / step)
    assert np.array_equal(ours, theirs)
    assert np.ptp(ours[:, 1]) > 1.0  # mm: the loop moved along the circle
    with pytest.raises(native.RunFailed, match="a pythonfmu FMU: load libpython first"):
        native.run(ssd, parameter_set="default", stop=stop, env={"LD_PRELOAD": ""})


def test_the_drive_loop_through_fmi3_gives_the_fmi2_trajectory_bit_for_bit(fmu_dir, slide_fmu):
    """Our FMI 3.0 SI FMUs (controller, drives, interpolator) with the pythonfmu slide (FMI
    2.0) in one fmpy master: the FMI 2.0 build's positions, bit for bit."""
    runs = [drive_loop(fmu_dir, slide_fmu, 1e-3, True, stop=0.5, build=build)
            for build in ("fmu-si", "fmu3-si")]
    assert np.array_equal(runs[0].view(np.uint64), runs[1].view(np.uint64))
