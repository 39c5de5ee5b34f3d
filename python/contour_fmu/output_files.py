"""Plumbing: files the demos write, CSV time series, and the FMI cross-check files of a
controller FMU (the inputs it received, the outputs it gave, the options to replay them)."""

import csv

import numpy as np


def write_csv(filename, columns):
    with open(filename, "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(list(columns))
        writer.writerows(zip(*columns.values()))


def write_cross_check(out, model, before, after, inputs, outputs, step):
    """OUT/cross-check/MODEL/: MODEL_in.csv (each input at t_k, from the master's `before`
    column named in `inputs` as (input, column)), MODEL_ref.csv (each output in `outputs`
    as reported after the step to t_k+1, with its start value 0 at t = 0) and
    MODEL_ref.opt."""
    directory = out / "cross-check" / model
    directory.mkdir(parents=True, exist_ok=True)
    columns = {"time": before["time"]}
    for ours, theirs in inputs:
        columns[ours] = before[theirs]
    write_csv(directory / f"{model}_in.csv", columns)
    results = {"time": np.concatenate([[0.0], after["time"]])}
    for name in outputs:
        results[name] = np.concatenate([[0.0], after[f"controller.{name}"]])
    write_csv(directory / f"{model}_ref.csv", results)
    stop = float(after["time"][-1])
    (directory / f"{model}_ref.opt").write_text(
        f"StartTime,0.0\nStopTime,{stop!r}\nStepSize,{step!r}\nRelTol,1e-6\n")
