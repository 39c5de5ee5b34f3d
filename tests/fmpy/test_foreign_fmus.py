"""FMUs a user brings that our masters cannot run are refused before anything runs, with a
message that names the file and says why: a plant exported for Model Exchange only (a
co-simulation master steps FMUs; Model Exchange needs a solver the FMU does not carry),
in the fmpy master, in a campaign and in the native master; an FMI 1.0 or 3.0 FMU in the
native master."""

import re
import shutil
import zipfile

import pytest

from contour_fmu.engines import native
from contour_fmu.campaign.spec import CampaignError, load
from contour_fmu.loops.ssp import SHIPPED
from contour_fmu.engines.master import closed_loop
from helpers.checkout import REPO


def model_exchange_only(source, target):
    """`source` with its <CoSimulation> element replaced by a <ModelExchange> one, as a
    Modelica tool's Model Exchange export declares it (the binary left as it is)."""
    with zipfile.ZipFile(source) as zin, zipfile.ZipFile(target, "w") as zout:
        for item in zin.infolist():
            data = zin.read(item.filename)
            if item.filename == "modelDescription.xml":
                xml = data.decode()
                xml, count = re.subn(r"<CoSimulation[^>]*/>",
                                     '<ModelExchange modelIdentifier="XYServoPlant"/>', xml)
                assert count == 1
                data = xml.encode()
            zout.writestr(item, data)


@pytest.fixture(scope="module")
def loop_with_a_model_exchange_plant(fmu_dir, tmp_path_factory):
    directory = tmp_path_factory.mktemp("me")
    for name in ("ContourCCC2D.fmu", "PathInterpolator2D.fmu"):
        shutil.copy2(fmu_dir / name, directory / name)
    model_exchange_only(fmu_dir / "XYServoPlant.fmu", directory / "XYServoPlant.fmu")
    return directory


def test_the_master_refuses_a_model_exchange_only_plant(loop_with_a_model_exchange_plant):
    plant = loop_with_a_model_exchange_plant / "XYServoPlant.fmu"
    with pytest.raises(ValueError, match="Model Exchange only") as refused:
        closed_loop(loop_with_a_model_exchange_plant, stop=0.01)
    assert str(plant) in str(refused.value)
    assert "Co-Simulation" in str(refused.value)


def test_a_campaign_refuses_a_model_exchange_only_plant(loop_with_a_model_exchange_plant):
    campaign = REPO / "examples" / "campaigns" / "two_axis_robustness.toml"
    with pytest.raises(CampaignError, match="Model Exchange only"):
        load(campaign, fmu_dir=loop_with_a_model_exchange_plant)


def ssd_file(name):
    return SHIPPED / f"{name}.ssd"


def test_the_native_master_refuses_a_model_exchange_only_plant(loop_with_a_model_exchange_plant, cosim):
    ssd = loop_with_a_model_exchange_plant / "two_axis.ssd"
    shutil.copy2(ssd_file("two_axis"), ssd)
    with pytest.raises(native.RunFailed, match="Model Exchange only") as refused:
        native.run(ssd, parameter_set="circle", stop=0.01)
    assert str(loop_with_a_model_exchange_plant / "XYServoPlant.fmu") in str(refused.value)


def test_the_native_master_refuses_fmi_1_and_3(fmu_dir, cosim, tmp_path):
    for version in ("1.0", "3.0"):
        folder = tmp_path / version
        folder.mkdir()
        for name in ("ContourCCC2D.fmu", "PathInterpolator2D.fmu"):
            shutil.copy2(fmu_dir / name, folder / name)
        with zipfile.ZipFile(fmu_dir / "XYServoPlant.fmu") as zin, \
                zipfile.ZipFile(folder / "XYServoPlant.fmu", "w") as zout:
            for item in zin.infolist():
                data = zin.read(item.filename)
                if item.filename == "modelDescription.xml":
                    data = data.replace(b'fmiVersion="2.0"', f'fmiVersion="{version}"'.encode())
                zout.writestr(item, data)
        shutil.copy2(ssd_file("two_axis"), folder / "two_axis.ssd")
        with pytest.raises(native.RunFailed, match=f"XYServoPlant.fmu: an FMI {version} FMU; this master "
                                                   "runs FMI 2.0 Co-Simulation FMUs"):
            native.run(folder / "two_axis.ssd", stop=0.01)
