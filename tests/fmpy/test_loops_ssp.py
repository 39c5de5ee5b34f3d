"""The loops as SSP 1.0 files (issue 25, step 1): contour_fmu/loops/*.ssd are what every
master wires (contour_fmu.loops.wiring reads them), and libcosim, an independent SSP reader,
runs them as they are: the same trajectories, bit for bit, as the loop the libcosim script
builds by hand, the parameter set of the default path applied by libcosim itself."""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from fmpy import read_model_description

from contour_fmu.loops import ssp
from contour_fmu.loops.wiring import FIVE_AXIS, TWO_AXIS
from helpers.fmu_slave import Slave

STEP_NS = 1_000_000
REPO = Path(__file__).resolve().parents[2]
SI = {name: ssp.read(ssp.SHIPPED / "si" / f"{name}.ssd") for name in ("two_axis", "five_axis")}


@pytest.mark.parametrize("structure, build", [(TWO_AXIS, "fmu"), (FIVE_AXIS, "fmu"),
                                              (SI["two_axis"], "fmu-si"),
                                              (SI["five_axis"], "fmu-si")],
                         ids=["two_axis", "five_axis", "two_axis-si", "five_axis-si"])
def test_each_paths_parameter_set_starts_the_plant_at_the_paths_first_sample(fmu_dir, structure,
                                                                             build):
    assert list(structure.parameter_sets)[0] in ("circle", "tilted_helix")  # the default
    for name, values in structure.parameter_sets.items():
        s = Slave(str(fmu_dir.parent / build / structure.units["interpolator"]))
        try:
            s.set(**values["interpolator"])
            s.fmu.exitInitializationMode()
            starts = {copy[3]: copy[1] for copy in structure.initial_copies}
            first = s.reals([starts[p] for p in values["plant"]])
            assert list(first) == list(values["plant"].values()), name
        finally:
            s.close()


def libcosim(fmu_dir, loop, steps, flags=(), assignments=()):
    done = subprocess.run(
        [sys.executable, "-m", "contour_fmu.engines.libcosim", "--loop", loop, *flags,
         str(fmu_dir), str(STEP_NS), str(steps), *assignments],
        capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-3000:]
    return json.loads(done.stdout.strip().splitlines()[-1])


@pytest.mark.parametrize("structure, steps", [(TWO_AXIS, 2000), (FIVE_AXIS, 600)],
                         ids=["two_axis", "five_axis"])
def test_libcosim_runs_the_shipped_ssp_as_the_loop_built_by_hand(fmu_dir, structure, steps):
    default = list(structure.parameter_sets)[0]
    by_hand = [f"{unit}.{variable}={value if isinstance(value, str) else repr(value)}"
               for unit, values in structure.start_values(default).items()
               for variable, value in values.items()]
    from_ssp = libcosim(fmu_dir, structure.name, steps, flags=["--ssp"])
    built = libcosim(fmu_dir, structure.name, steps, assignments=by_hand)
    assert from_ssp["series"].keys() == built["series"].keys()
    for name, values in built["series"].items():
        assert np.array_equal(from_ssp["series"][name], values), name
    # The default path's plant start applied (the five-axis one is not at the origin).
    if structure is FIVE_AXIS:
        assert abs(from_ssp["series"]["plant.pos.Y"][0] + 46.98) < 0.1


def test_the_si_files_are_the_mm_files_in_metres():
    """The SI build's SSP files are written from the mm ones (python -m contour_fmu.loops.ssp):
    the same wiring, lengths scaled by the SI model descriptions' units."""
    for name, si in SI.items():
        mm = ssp.shipped(name)
        assert si.file.read_text() == ssp.si_variant(mm.file, REPO / "modelDescription")
        assert (si.units, si.order, si.connections, si.initial_copies) == (
            mm.units, mm.order, mm.connections, mm.initial_copies)


def test_libcosim_runs_the_si_loop_as_the_mm_loop_in_metres(fmu_dir):
    """The five-axis loop from its SI file beside the SI FMUs, in libcosim: the mm loop's
    trajectories, lengths in m, to the rounding of the interface's scaling."""
    mm = libcosim(fmu_dir, "five_axis", 300, flags=["--ssp"])
    si = libcosim(fmu_dir.parent / "fmu-si", "five_axis", 300, flags=["--ssp"])
    units = {}
    for unit, file in SI["five_axis"].units.items():
        md = read_model_description(str(fmu_dir.parent / "fmu-si" / file))
        units.update({f"{unit}.{v.name}": v.unit for v in md.modelVariables})
    for name, values in mm["series"].items():
        if name.startswith("controller.evaluation"):
            continue  # a diagnostic that amplifies rounding (recorded in issue 24's note)
        scale = 1e-3 if units[name] in ("m", "m/s") else 1.0
        want = np.array(values) * scale
        worst = np.abs(np.array(si["series"][name]) - want).max() / np.abs(want).max()
        # The trajectories to the interface's rounding; the controller's outputs (its
        # gains amplify it) within 1e-9 of their largest (u.A is itself rounding: the
        # helix keeps A still;
        # the shipped loop's feed-forward carries the rounding of aref.A into u.A.)
        tolerance = 1e-12 if name.startswith(("plant", "interpolator")) else 1e-9
        assert worst < (1e-8 if name == "controller.u.A" else tolerance), name


def write(tmp_path, text):
    file = tmp_path / "loop.ssd"
    file.write_text(text)
    return file


def test_a_malformed_or_inconsistent_ssd_is_refused_naming_the_file(tmp_path):
    shipped = TWO_AXIS.file.read_text()
    cases = [
        (shipped[:500], "not a readable system structure description"),
        (shipped.replace('version="1.0" name="two_axis"', 'version="2.0" name="two_axis"'),
         "not an SSP 1.0"),
        (shipped.replace('endConnector="pos.x"/>', 'endConnector="pos.z"/>', 1),
         "controller.pos.z, which is not among controller's connectors"),
        (shipped.replace('startElement="plant" startConnector="pos.y"',
                         'startElement="table" startConnector="pos.y"', 1),
         "component 'table', which is not one"),
        (shipped.replace('order="controller plant interpolator"', 'order="controller plant"'),
         "does not list each component once"),
        (shipped.replace('<ssv:Real value="40.2"/>', '<ssv:Real value="forty"/>'),
         "plant.pos0.x: 'forty' is no Real"),
        (shipped.replace('<ssv:Real value="40.2"/>', '<ssv:Enumeration value="1"/>'),
         "plant.pos0.x: a parameter needs one value of type"),
    ]
    for text, words in cases:
        file = write(tmp_path, text)
        with pytest.raises(ValueError, match=words) as refused:
            ssp.read(file)
        assert str(file) in str(refused.value)
    with pytest.raises(ValueError, match="no parameter set 'spiral'"):
        TWO_AXIS.start_values("spiral")
    with pytest.raises(ValueError, match="not a readable"):
        ssp.read(tmp_path / "missing.ssd")
