"""Closed-loop demo: the paper's circle tracked by XYServoPlant under a P position loop.

A small fixed-step master on fmpy's FMU2Slave: every 1 ms the reference point of the
circle x = 10 cos(pi t) - 10, y = 10 sin(pi t) is compared with the measured position,
and Kpp times the following error is sent to the drives as a velocity command. Prints
the maximum contour error (distance to the circle) and writes out/demo_circle.csv and
out/demo_circle.png. (The cross-coupled controller FMU replaces the P loop later.)
"""

import csv
import shutil
import tempfile
from pathlib import Path

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

REPO = Path(__file__).resolve().parents[2]
FMU = REPO / "target" / "fmu" / "XYServoPlant.fmu"
OUT = REPO / "out"
TS, STOP, KPP, RADIUS = 1e-3, 2.0, 28.5, 10.0


def reference(t):
    return np.array([RADIUS * np.cos(np.pi * t) - RADIUS, RADIUS * np.sin(np.pi * t)])


def main():
    md = read_model_description(str(FMU))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    unzipped = extract(str(FMU))
    plant = FMU2Slave(guid=md.guid, unzipDirectory=unzipped,
                      modelIdentifier=md.coSimulation.modelIdentifier, instanceName="plant")
    plant.instantiate()
    plant.setupExperiment(startTime=0.0, stopTime=STOP)
    plant.enterInitializationMode()
    plant.exitInitializationMode()
    rows = []
    steps = int(round(STOP / TS))
    for k in range(steps):
        t = k * TS
        pos = np.array(plant.getReal([vr["pos.x"], vr["pos.y"]]))
        ref = reference(t)
        u = KPP * (ref - pos)
        plant.setReal([vr["u.x"], vr["u.y"]], list(u))
        plant.doStep(currentCommunicationPoint=t, communicationStepSize=TS)
        contour = np.hypot(pos[0] + RADIUS, pos[1]) - RADIUS
        rows.append((t, ref[0], ref[1], pos[0], pos[1], contour))
    plant.terminate()
    plant.freeInstance()
    shutil.rmtree(unzipped, ignore_errors=True)

    data = np.array(rows)
    settled = data[data[:, 0] >= 0.1]
    print(f"XYServoPlant + P position loop (Kpp = {KPP} 1/s) on the paper's circle, Ts = {TS * 1e3:g} ms")
    print(f"  max |contour error| after 0.1 s: {np.max(np.abs(settled[:, 5])) * 1e3:.2f} um")
    print(f"  mean |contour error|:            {np.mean(np.abs(settled[:, 5])) * 1e3:.2f} um")
    OUT.mkdir(exist_ok=True)
    with open(OUT / "demo_circle.csv", "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(["time", "ref.x", "ref.y", "pos.x", "pos.y", "contourError"])
        writer.writerows(rows)
    import matplotlib.pyplot as plt

    fig, (a, b) = plt.subplots(1, 2, figsize=(10, 4.5))
    a.plot(data[:, 1], data[:, 2], label="reference")
    a.plot(data[:, 3], data[:, 4], "--", label="actual")
    a.set_aspect("equal"), a.set_xlabel("x (mm)"), a.set_ylabel("y (mm)"), a.legend()
    b.plot(data[:, 0], data[:, 5] * 1e3)
    b.set_xlabel("time (s)"), b.set_ylabel("contour error (um)")
    fig.tight_layout()
    fig.savefig(OUT / "demo_circle.png", dpi=120)
    print(f"  wrote {OUT / 'demo_circle.csv'} and {OUT / 'demo_circle.png'}")


if __name__ == "__main__":
    main()
