"""The stepping loop of the master and the campaigns (contour_fmu.engines.stepping) gives, to the
bit, what the plain loop gives: one get and one set per variable and connection."""

import numpy as np
import pytest

from contour_fmu.loops.wiring import LOOPS
from contour_fmu.engines.master import Master, Unit
from contour_fmu.engines.stepping import SCHEMES

STEP, STOP = 1e-3, 0.3
ORDER = ("controller", "plant", "interpolator")


def plain_loop(master, record, scheme):
    """The loop one variable at a time (contour_fmu.engines.master's before it shared the loop)."""
    before, after = [], []
    for k in range(int(round(STOP / STEP))):
        t = k * STEP
        before.append([master.get(u, v) for u, v in record])
        if scheme == "jacobi":
            for src, out, dst, inp in master.connections:
                master.set(dst, inp, master.get(src, out))
        for unit in ORDER:
            if scheme == "gauss-seidel":
                for src, out, dst, inp in master.connections:
                    if dst == unit:
                        master.set(dst, inp, master.get(src, out))
            master.slaves[unit].doStep(currentCommunicationPoint=t, communicationStepSize=STEP)
        after.append([master.get(u, v) for u, v in record])
    return np.array(before), np.array(after)


@pytest.mark.parametrize("scheme", SCHEMES)
@pytest.mark.parametrize("loop", list(LOOPS))
def test_the_stepping_loop_gives_what_one_call_per_variable_gives(fmu_dir, loop, scheme):
    loop = LOOPS[loop]
    record = loop.recorded + [("interpolator", "done")]  # a Boolean column as well

    def master():
        units = [Unit(u, str(fmu_dir / loop.units[u])) for u in ORDER]
        return Master(units, loop.connections, STEP, STOP, scheme, initial=loop.path_start)

    with master() as m:
        before, after = m.run(record)
    with master() as m:
        expected_before, expected_after = plain_loop(m, record, scheme)
    for rows, expected in ((before, expected_before), (after, expected_after)):
        columns = np.column_stack([rows[f"{u}.{v}"] for u, v in record])
        assert np.array_equal(columns, expected)
    position = next(f"{u}.{v}" for u, v in record if u == "plant")
    assert np.ptp(before[position]) > 0  # the loop moved
