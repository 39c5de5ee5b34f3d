"""Engine: the fixed-step stepping loop of the fmpy master (contour_fmu.engines.master) and
of the campaigns' runner: fmpy slaves (FMI 2.0 or 3.0) stepped one communication step at a time in a given
order, their connections and the recorded variables resolved to value references once.

Two coupling schemes (contour_fmu.engines.master explains them): "gauss-seidel", each
FMU's inputs set from their sources just before it steps; "jacobi", every input set from
the outputs at t_k, then every FMU steps. Consecutive connections between the same two
FMUs (of the same types) are transferred with one get and one set, and consecutive
recorded variables of one FMU and type read with one get: the values are those of one
call per variable.
"""

from .slaves import PYTHON_TYPES, accessors, kind

SCHEMES = ("gauss-seidel", "jacobi")


class Stepping:
    """The loop over `slaves` (unit -> fmpy slave of either standard, in stepping order)."""

    def __init__(self, slaves, variables, connections, scheme="gauss-seidel"):
        """variables: unit -> {name: fmpy model variable}; connections: (source unit,
        output name, destination unit, input name)."""
        if scheme not in SCHEMES:
            raise ValueError(f"unknown coupling scheme {scheme!r}; expected one of {SCHEMES}")
        self.slaves, self.variables = slaves, variables
        if scheme == "jacobi":
            self.first = self._transfers(connections)
            self.stepped = [(slave.doStep, []) for slave in slaves.values()]
        else:
            self.first = []
            self.stepped = [(slave.doStep, self._transfers([c for c in connections if c[2] == unit]))
                            for unit, slave in slaves.items()]

    def _transfers(self, connections):
        """[(get, source vrs, set, destination vrs)] in the connections' order."""
        groups, last = [], None
        for src, out, dst, inp in connections:
            source, target = self.variables[src][out], self.variables[dst][inp]
            key = (src, dst, source.type, target.type)
            if key != last or src == dst:
                get, _ = accessors(self.slaves[src], source.type)
                _, put = accessors(self.slaves[dst], target.type)
                if kind(source.type) != kind(target.type):
                    get = lambda vrs, get=get, convert=PYTHON_TYPES[kind(target.type)]: [  # noqa: E731
                        convert(v) for v in get(vrs)]
                groups.append((get, [], put, []))
            groups[-1][1].append(source.valueReference)
            groups[-1][3].append(target.valueReference)
            last = key
        return groups

    def _reads(self, columns):
        """[(get, vrs)] that read `columns` ((unit, name)) in their order."""
        reads, last = [], None
        for unit, name in columns:
            variable = self.variables[unit][name]
            key = (unit, variable.type)
            if key != last:
                reads.append((accessors(self.slaves[unit], variable.type)[0], []))
            reads[-1][1].append(variable.valueReference)
            last = key
        return reads

    def run(self, step, steps, before=(), after=(), ended=None, settle=0):
        """Steps from t = 0: `steps` steps; or, with `ended` (a function asked before each
        step until it answers true), `settle` steps more from the first step k at which
        it does, which must come within `steps` steps. Returns (k, rows before, rows
        after): the number of steps taken (None when `ended` never answered true), and
        per step the values of the `before` columns ((unit, name)) at t_k and of the
        `after` columns once every FMU has stepped to t_k+1."""
        read_before, read_after = self._reads(before), self._reads(after)
        first, stepped = self.first, self.stepped
        rows_before, rows_after = [], []
        limit, waiting, k = steps, ended is not None, 0
        while k < limit:
            if waiting and ended():
                limit, waiting = k + settle, False
                continue
            t = k * step
            row = []
            for get, vrs in read_before:
                row.extend(get(vrs))
            rows_before.append(row)
            for get, source, put, target in first:
                put(target, get(source))
            for do_step, transfers in stepped:
                for get, source, put, target in transfers:
                    put(target, get(source))
                do_step(currentCommunicationPoint=t, communicationStepSize=step)
            row = []
            for get, vrs in read_after:
                row.extend(get(vrs))
            rows_after.append(row)
            k += 1
        return (None if waiting else k), rows_before, rows_after
