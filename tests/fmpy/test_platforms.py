"""The FMUs for the platforms users model on: every FMU of `fmu-build --platforms all` (what
`make fmus-all` ships) carries linux64, win64 and aarch64-linux binaries of one build
(FMI 3.0's: x86_64-linux, x86_64-windows, aarch64-linux, the same libraries), and the
win64 binary under Wine and the aarch64 binary under QEMU compute what the linux64 binary
computes, bit for bit: the loops through each platform's contour-cosim, the bad-input
catalogue's statuses and messages, saved states carried from one platform to another,
resource locations with a drive and a share, and FMI 3.0 calls, which compute what FMI 2.0
calls do. The binaries are read by binutils (objdump), not by the packager's own reader."""

import os
import re
import shutil
import subprocess
import zipfile
from pathlib import Path

import pytest
from fmpy import read_model_description
from fmpy.validation import validate_fmu

from helpers.checkout import REPO, target_dir

PLATFORMS = ("linux64", "win64", "aarch64-linux")
# FMI 3.0's names of the same platforms (its binaries/ folders).
FMI3_PLATFORMS = {"linux64": "x86_64-linux", "win64": "x86_64-windows",
                  "aarch64-linux": "aarch64-linux"}
TRIPLES = {"linux64": "x86_64-unknown-linux-gnu", "win64": "x86_64-pc-windows-gnu",
           "aarch64-linux": "aarch64-unknown-linux-gnu"}
EXTENSIONS = {"linux64": "so", "win64": "dll", "aarch64-linux": "so"}
RUNNERS = {"linux64": [], "win64": ["wine"],
           "aarch64-linux": ["qemu-aarch64", "-L", "/usr/aarch64-linux-gnu"]}
COMPILERS = {"linux64": "gcc", "win64": "x86_64-w64-mingw32-gcc",
             "aarch64-linux": "aarch64-linux-gnu-gcc"}
OBJDUMPS = {"linux64": "objdump", "win64": "x86_64-w64-mingw32-objdump",
            "aarch64-linux": "aarch64-linux-gnu-objdump"}
PROBE = REPO / "tests" / "platforms" / "fmi_probe.c"
# Wine 8.0 has no bcryptprimitives.dll, whose ProcessPrng Rust's standard library calls on
# Windows 10 and later (real Windows has it): a test-only stand-in beside the programs.
SHIM = r"""
#include <windows.h>
#include <ntsecapi.h>
__declspec(dllexport) BOOL WINAPI ProcessPrng(PBYTE data, SIZE_T size) {
    return RtlGenRandom(data, (ULONG)size);
}
"""


@pytest.fixture(scope="module")
def distribution():
    """`fmu-build --platforms all` into <target>/fmu-platforms (cargo: a no-op when built):
    the mm FMUs there, the SI ones in fmu-platforms-si, each platform's contour-cosim in
    <target>/cross/<triple>/release."""
    out = target_dir() / "fmu-platforms"
    command = ["cargo", "run", "--quiet", "--release", "-p", "fmu-build", "--",
               "--platforms", "all", "--out", str(out)]
    done = subprocess.run(command, cwd=REPO, capture_output=True, text=True)
    assert done.returncode == 0, f"{' '.join(command)} failed:\n{done.stdout}\n{done.stderr}"
    return out


@pytest.fixture(scope="module")
def programs(distribution, tmp_path_factory):
    """Per platform: a folder with fmi_probe, contour-cosim and (win64) the shim, and the
    command prefix that runs programs of that platform here."""
    root = tmp_path_factory.mktemp("programs")
    prefix = root / "wineprefix"
    os.environ.setdefault("WINEDEBUG", "-all")
    os.environ["WINEPREFIX"] = str(prefix)
    folders = {}
    for platform in PLATFORMS:
        folder = root / platform
        folder.mkdir()
        exe = ".exe" if platform == "win64" else ""
        subprocess.run([COMPILERS[platform], "-O2", "-Wall", "-I", str(REPO / "third_party" / "fmi2"),
                        "-I", str(REPO / "third_party" / "fmi3"),
                        "-o", str(folder / f"fmi_probe{exe}"), str(PROBE)]
                       + ([] if platform == "win64" else ["-ldl"]), check=True)
        cosim = target_dir() / "cross" / TRIPLES[platform] / "release" / f"contour-cosim{exe}"
        shutil.copy2(cosim, folder / cosim.name)
        if platform == "win64":
            (root / "shim.c").write_text(SHIM)
            subprocess.run([COMPILERS[platform], "-shared", "-O2", "-o",
                            str(folder / "bcryptprimitives.dll"), str(root / "shim.c"),
                            "-ladvapi32"], check=True)
        folders[platform] = folder
    return folders


def run(platform, programs, program, *args, check=True):
    exe = ".exe" if platform == "win64" else ""
    command = RUNNERS[platform] + [str(programs[platform] / f"{program}{exe}"), *map(str, args)]
    done = subprocess.run(command, capture_output=True, text=True, timeout=600)
    if check:
        assert done.returncode == 0, f"{command}: {done.returncode}\n{done.stdout}\n{done.stderr}"
    return done


def unpacked(fmu, folder):
    with zipfile.ZipFile(fmu) as archive:
        archive.extractall(folder)
    return folder


def library(folder, platform, identifier, fmi3=False):
    return (folder / "binaries" / (FMI3_PLATFORMS[platform] if fmi3 else platform)
            / f"{identifier}.{EXTENSIONS[platform]}")


def all_fmus(distribution, fmi3=False):
    """The FMI 2.0 FMUs of the distribution (mm, then SI), or its FMI 3.0 ones."""
    first = Path(f"{distribution}3") if fmi3 else distribution
    return sorted(first.glob("*.fmu")) + sorted(Path(f"{first}-si").glob("*.fmu"))


@pytest.mark.parametrize("fmi3", [False, True], ids=["FMI 2.0", "FMI 3.0"])
def test_every_fmu_carries_three_platforms_of_one_build(distribution, tmp_path, fmi3):
    fmus = all_fmus(distribution, fmi3)
    assert len(fmus) == 16
    builds = set()
    for fmu in fmus:
        md = read_model_description(str(fmu))
        assert md.fmiVersion == ("3.0" if fmi3 else "2.0"), fmu
        identifier = md.coSimulation.modelIdentifier
        folder = unpacked(fmu, tmp_path / fmu.parent.name / fmu.stem)
        folders = [FMI3_PLATFORMS[p] if fmi3 else p for p in PLATFORMS]
        assert sorted(p.name for p in (folder / "binaries").iterdir()) == sorted(folders)
        for platform in PLATFORMS:
            data = library(folder, platform, identifier, fmi3).read_bytes()
            found = re.findall(rb"contour-fmu build ([0-9a-f]{32})", data)
            assert len(found) == 1, (fmu, platform)
            builds.add(found[0])
    assert len(builds) == 1, "every binary of every FMU comes from one source tree"


def exports(platform, path):
    """The exported function names, as binutils reads them."""
    text = subprocess.run([OBJDUMPS[platform], "-p" if platform == "win64" else "-T", str(path)],
                          capture_output=True, text=True, check=True).stdout
    if platform == "win64":
        table = text.split("[Ordinal/Name Pointer] Table", 1)[1].split("\n\n", 1)[0]
        return set(re.findall(r"^\s*\[\s*\d+\]\s+(\w+)\s*$", table, re.M))
    return {line.split()[-1] for line in text.splitlines()
            if " DF .text" in line and " g " in line}


def test_each_binary_exports_the_fmi2_and_fmi3_functions_and_linux_needs_glibc_2_28(
        distribution, tmp_path):
    header = (REPO / "third_party" / "fmi2" / "fmi2Functions.h").read_text()
    # The standard's own list: the FMI2_Export declarations of the header, less Model
    # Exchange's functions (section 3.2.2 of FMI 2.0.4), which these FMUs do not provide.
    model_exchange = {"fmi2EnterEventMode", "fmi2NewDiscreteStates", "fmi2EnterContinuousTimeMode",
                      "fmi2CompletedIntegratorStep", "fmi2SetTime", "fmi2SetContinuousStates",
                      "fmi2GetDerivatives", "fmi2GetEventIndicators", "fmi2GetContinuousStates",
                      "fmi2GetNominalsOfContinuousStates"}
    standard = set(re.findall(r"FMI2_Export (fmi2\w+)TYPE", header)) - model_exchange
    assert len(standard) == 34
    # And every function FMI 3.0's header exports (importers look each one up).
    fmi3 = set(re.findall(r"FMI3_Export fmi3\w+TYPE\s+(fmi3\w+);",
                          (REPO / "third_party" / "fmi3" / "fmi3Functions.h").read_text()))
    assert len(fmi3) == 75
    standard |= fmi3
    folder = unpacked(distribution / "ContourCCC2D.fmu", tmp_path / "ccc")
    for platform in PLATFORMS:
        path = library(folder, platform, "ContourCCC2D")
        assert exports(platform, path) == standard, platform
        if platform != "win64":
            text = subprocess.run([OBJDUMPS[platform], "-p", str(path)], capture_output=True,
                                  text=True, check=True).stdout
            versions = [tuple(map(int, v.split(".")[:2]))
                        for v in re.findall(r"GLIBC_(\d+\.\d+(?:\.\d+)?)", text)]
            assert versions and max(versions) <= (2, 28), (platform, max(versions))
        else:
            imports = set(re.findall(r"DLL Name: (\S+)", subprocess.run(
                [OBJDUMPS[platform], "-p", str(path)], capture_output=True, text=True,
                check=True).stdout))
            # System DLLs only: nothing of mingw's or gcc's runtime to ship beside it.
            assert not {d for d in imports if re.match(r"(?i)lib(gcc|stdc|winpthread)", d)}, imports


def test_fmpy_validates_the_multi_platform_fmus(distribution):
    for fmu in all_fmus(distribution) + all_fmus(distribution, fmi3=True):
        assert validate_fmu(str(fmu)) == [], fmu


PART = REPO / "examples" / "parts" / "bracket.ngc"
# The loops as users run them: the paper's trident, the five-axis example part and a helix,
# and a G-code part planned within acceleration and jerk limits (the planner's polynomial
# roots take cube roots and arc cosines).
LOOP_RUNS = {
    "trident": ("two_axis", ["--parameter-set", "trident"]),
    "planned part": ("two_axis", ["--parameter-set", "trident",
                                  "--start", "interpolator.path={PART}",
                                  "--start", "interpolator.accel=2000",
                                  "--start", "interpolator.jerk=100000"]),
    "blade.cl": ("five_axis", ["--parameter-set", "blade.cl"]),
    "tilted helix": ("five_axis", ["--parameter-set", "tilted_helix"]),
}


@pytest.mark.parametrize("name", sorted(LOOP_RUNS))
def test_the_loops_run_bit_for_bit_on_every_platform(distribution, programs, name, tmp_path):
    loop, options = LOOP_RUNS[name]
    results = {}
    for platform in PLATFORMS:
        out = tmp_path / f"{platform}.csv"
        # A Windows program reads the part from Wine's drive Z:, the Unix root.
        part = f"Z:{PART}" if platform == "win64" else str(PART)
        arguments = [o.replace("{PART}", part) for o in options]
        run(platform, programs, "contour-cosim", "run", distribution / f"{loop}.ssd", *arguments,
            "--until", "interpolator.done", "--settle", "0.05", "--output", out)
        results[platform] = out.read_bytes()
    assert results["linux64"].count(b"\n") > 1000
    for platform in PLATFORMS[1:]:
        assert results[platform] == results["linux64"], f"{platform} differs from linux64"


def vrs(fmu):
    return {v.name: v.valueReference for v in read_model_description(str(fmu)).modelVariables}


def probe(platform, programs, folder, identifier, *script, fmi3=False):
    done = run(platform, programs, "fmi_probe", library(folder, platform, identifier, fmi3),
               *script, check=False)
    assert done.returncode == 0, f"{platform}: {done.stdout}\n{done.stderr}"
    return done.stdout


def test_bad_inputs_answer_alike_on_every_platform(distribution, programs, tmp_path):
    fmu = distribution / "ContourCCC2D.fmu"
    md = read_model_description(str(fmu))
    folder = unpacked(fmu, tmp_path / "ccc")
    v = vrs(fmu)
    # Each script, and what the answer must say on every platform.
    scripts = {
        "wrong GUID": (["inst", "c", "{00000000-0000-0000-0000-000000000000}", "-"],
                       ["unknown GUID {00000000-0000-0000-0000-000000000000}",
                        "instantiate -> NULL"]),
        "no callbacks": (["inst-no-callbacks", md.guid], ["instantiate -> NULL"]),
        "call order": (["inst", "c", md.guid, "-", "step", "0", "0.001", "exit", "enter",
                        "getr", v["u.x"], "free"],
                       ["fmi2DoStep: illegal call sequence (state Instantiated)", "step -> 3",
                        "exit -> 3", "enter -> 0"]),
        "NaN input": (["inst", "c", md.guid, "-", "setup", "0", "enter", "exit",
                       "setr", v["pos.x"], "nan", "setr", v["ref.x"], "inf", "step", "0", "0.001",
                       "getr", v["u.x"], "free"],
                      ["variable 'pos.x' refuses the non-finite value NaN",
                       "variable 'ref.x' refuses the non-finite value inf", "setr -> 3",
                       "step -> 0"]),
        "corrupt state": (["inst", "c", md.guid, "-", "setup", "0", "enter", "exit",
                           "load-corrupt", "step", "0", "0.001", "getr", v["u.x"], "free"],
                          ["the bytes are not an FMU state of this library", "deserialize -> 3",
                           "step -> 0"]),
        "unknown reference": (["inst", "c", md.guid, "-", "setup", "0", "enter", "exit",
                               "getr", "99999", "setr", v["Ts"], "-1", "free"],
                              ["getr -> 3", "setr -> 3", "99999"]),
    }
    for name, (script, expected) in scripts.items():
        transcripts = {p: probe(p, programs, folder, "ContourCCC2D", *script) for p in PLATFORMS}
        for fragment in expected:
            assert fragment in transcripts["linux64"], f"{name}: {fragment!r}\n{transcripts['linux64']}"
        for platform in PLATFORMS[1:]:
            assert transcripts[platform] == transcripts["linux64"], \
                f"{name}: {platform}\n{transcripts[platform]}\nlinux64\n{transcripts['linux64']}"


def test_resource_locations_with_a_drive_and_a_share_under_wine(distribution, programs, tmp_path):
    """The CL part of PathInterpolator5X's resources/ is found through a Windows URI with a
    drive (Wine's Z: is the Unix root), also written with backslashes, and read as on
    Linux; a share's host is the UNC path Windows means by it."""
    fmu = distribution / "PathInterpolator5X.fmu"
    md = read_model_description(str(fmu))
    folder = unpacked(fmu, tmp_path / "p5")
    v = vrs(fmu)
    resources = folder / "resources"
    script = ["sets", v["path"], "blade.cl", "setup", "0", "enter", "exit",
              "steps", 200, 0, 0.001, 2, v["ref.X"], v["ref.C"], "free"]
    linux = probe("linux64", programs, folder, "PathInterpolator5X", "inst", "p", md.guid,
                  resources.as_uri(), *script)
    assert linux.count("real ") == 400 and "exit -> 0" in linux
    for uri in (f"file:///Z:{resources}/", "file:///Z:" + str(resources).replace("/", "\\")):
        windows = probe("win64", programs, folder, "PathInterpolator5X", "inst", "p", md.guid,
                        uri, *script)
        assert windows == linux, uri
    share = probe("win64", programs, folder, "PathInterpolator5X", "inst", "p", md.guid,
                  "file://fileserver/models/ccc/resources", *script[:7])
    assert "\\\\fileserver\\models\\ccc\\resources\\blade.cl: cannot read" in share, share
    assert "exit -> 3" in share


# Models, parameters set before initialization, the inputs set before stepping, and the
# outputs compared after each step (all of which move: the controller's axis loops
# integrate the held error).
STATE_CASES = {
    "XYServoPlant": ({}, {"u.x": "12.5", "u.y": "-7.25"}, ["pos.x", "pos.y", "vel.x", "vel.y"]),
    "ContourCCC2D": ({"axis.x.Ki": "20", "axis.y.Ki": "20"},
                     {"ref.x": "1.0", "ref.y": "0.5", "pos.x": "0.9", "pos.y": "0.6"},
                     ["u.x", "u.y", "err.x", "err.y"]),
    "PathInterpolator5X": ({}, {}, ["ref.X", "ref.Y", "ref.Z", "ref.A", "ref.C"]),
    "PathInterpolator2D": ({}, {}, ["ref.x", "ref.y", "vref.x", "aref.y"]),
}


@pytest.mark.parametrize("identifier", sorted(STATE_CASES))
def test_a_state_saved_on_one_platform_continues_bit_for_bit_on_the_others(
        distribution, programs, identifier, tmp_path):
    fmu = distribution / f"{identifier}.fmu"
    md = read_model_description(str(fmu))
    folder = unpacked(fmu, tmp_path / identifier)
    v = vrs(fmu)
    parameters, inputs, outputs = STATE_CASES[identifier]
    tuning = [word for name, value in parameters.items() for word in ("setr", v[name], value)]
    setting = [word for name, value in inputs.items() for word in ("setr", v[name], value)]
    uri = (folder / "resources").as_uri()
    start = ["inst", "s", md.guid, uri, *tuning, "setup", "0", "enter", "exit", *setting]
    watched = [v[name] for name in outputs]
    saved, continued = {}, {}
    for platform in PLATFORMS:
        saved[platform] = tmp_path / f"{platform}.state"
        transcript = probe(platform, programs, folder, identifier, *start,
                           "steps", 300, 0, 0.001, 0, "save", saved[platform],
                           "steps", 300, 0.3, 0.001, len(watched), *watched)
        continued[platform] = transcript.split("free state -> 0\n", 1)[1]
    first = saved["linux64"].read_bytes()
    for platform in PLATFORMS[1:]:
        assert saved[platform].read_bytes() == first, f"{platform} saves other bytes"
        assert continued[platform] == continued["linux64"], platform
    assert continued["linux64"].count("real") == 300 * len(watched)
    # The watched outputs move after the restore: equal transcripts are not equal constants.
    values = {line for line in continued["linux64"].splitlines() if line.startswith("real ")}
    assert len(values) > 2 * len(watched), sorted(values)[:12]
    # Restored into a fresh instance of every platform from the others' states.
    for saver in PLATFORMS:
        for loader in PLATFORMS:
            if saver == loader:
                continue
            transcript = probe(loader, programs, folder, identifier, *start, "load",
                               saved[saver], "steps", 300, 0.3, 0.001, len(watched), *watched)
            assert transcript.split("free state -> 0\n", 1)[1] == continued["linux64"], \
                f"saved by {saver}, restored by {loader}"


def test_fmi3_calls_compute_what_fmi2_calls_do_on_every_platform(distribution, programs, tmp_path):
    """ContourCCC2D through fmi3 on each platform: the FMI 2.0 transcript's values, bit for
    bit, steps and a state saved and restored through FMI 3.0 included."""
    fmu2, fmu3 = distribution / "ContourCCC2D.fmu", Path(f"{distribution}3") / "ContourCCC2D.fmu"
    guid, token = read_model_description(str(fmu2)).guid, \
        read_model_description(str(fmu3)).instantiationToken
    v = vrs(fmu2)
    assert vrs(fmu3) == {**v, "time": len(v)}
    inputs = [("pos.x", "0.25"), ("ref.x", "1"), ("ref.y", "0.5")]
    # 100 steps from 0, then 50 from 0.1, reading three outputs after each.
    read = [v["u.x"], v["u.y"], v["contourError"]]
    first, then = ["100", "0", "0.001", "3", *read], ["50", "0.1", "0.001", "3", *read]
    folders = {3: unpacked(fmu3, tmp_path / "three"), 2: unpacked(fmu2, tmp_path / "two")}
    for platform in PLATFORMS:
        state = tmp_path / f"{platform}.state"
        # A Windows program reads the state through Wine's drive Z:, the Unix root.
        state_arg = f"Z:{state}" if platform == "win64" else str(state)
        three = ["inst3", "c", token, "-", "enter3", "0", "exit3",
                 *[a for name, x in inputs for a in ("setr3", v[name], x)],
                 "steps3", *first, "save3", state_arg, "steps3", *then,
                 "load3", state_arg, "steps3", *then, "free3"]
        two = ["inst", "c", guid, "-", "setup", "0", "enter", "exit",
               *[a for name, x in inputs for a in ("setr", v[name], x)],
               "steps", *first, "steps", *then, "free"]
        transcript3 = probe(platform, programs, folders[3], "ContourCCC2D", *three, fmi3=True)
        transcript2 = probe(platform, programs, folders[2], "ContourCCC2D", *two)
        reals3 = [line for line in transcript3.splitlines() if line.startswith("real ")]
        reals2 = [line for line in transcript2.splitlines() if line.startswith("real ")]
        assert len(reals2) == 3 * 150, platform
        # FMI 3.0: 100 steps, 50 more, then the same 50 again from the restored state.
        assert reals3 == reals2 + reals2[-150:], platform
        assert "deserialize -> 0" in transcript3 and "set state -> 0" in transcript3
