"""Reference check: the package's one G-code reader, the programmed part read in Python
independently of the Rust reader and the FMUs: its lines and arcs in closed form
(`read_program`, the subset the demo's programs use), their joins, the exact distance of
points to them (the part demo's true contour error) and the program's mirror image
(`mirror_program`: y -> -y, J -> -J, G2 <-> G3).
"""

import math
import re
from dataclasses import dataclass

import numpy as np

TANGENT = 1e-3  # rad: joins turning less than this are tangent (the planner's MIN_BLEND_TURN)


@dataclass
class Piece:
    """One move of a program: a line (start, end) or an arc (centre, radius, start angle,
    signed sweep: > 0 counter-clockwise), with the program line it comes from, its feed
    (mm/s; None before the first F) and the corner mode at its end ("stop", "blend" with
    `blend` = P in mm, or "default": bare G64 / the parameter)."""
    kind: str
    start: np.ndarray
    end: np.ndarray
    line: int
    feed: float | None
    corner: str
    blend: float | None = None
    centre: np.ndarray | None = None
    radius: float = 0.0
    start_angle: float = 0.0
    sweep: float = 0.0
    label: str = ""

    @property
    def length(self):
        if self.kind == "line":
            return float(np.linalg.norm(self.end - self.start))
        return self.radius * abs(self.sweep)

    def tangent(self, u):
        """The unit tangent at the local parameter u in [0, 1]."""
        if self.kind == "line":
            d = self.end - self.start
            return d / np.linalg.norm(d)
        phi = self.start_angle + u * self.sweep
        return math.copysign(1.0, self.sweep) * np.array([-math.sin(phi), math.cos(phi)])

    def as_tuple(self):
        """("line", start, end) or ("arc", centre, radius, start angle, sweep)."""
        if self.kind == "line":
            return ("line", tuple(self.start), tuple(self.end))
        return ("arc", tuple(self.centre), self.radius, self.start_angle, self.sweep)


class ProgramError(ValueError):
    pass


_WORD = re.compile(r"([A-Za-z])\s*([-+]?(?:\d+\.?\d*|\.\d+))")
_SKIPPED_G = {40, 49, 80, 94, 54, 55, 56, 57, 58, 59, 17}
_SKIPPED_M = {3, 4, 5, 6, 7, 8, 9}


def _code(line):
    """A block without its comments: `( )` and what follows `;`."""
    return re.sub(r"\([^)]*\)", " ", line).split(";", 1)[0]


def _arc_centre(start, end, radius, clockwise):
    chord = end - start
    length = float(np.linalg.norm(chord))
    h = math.sqrt(max(radius * radius - length * length / 4.0, 0.0))
    left = np.array([-chord[1], chord[0]]) / length
    # A counter-clockwise arc of at most 180° (R > 0) turns about a centre left of its
    # chord; negative R (over 180°) or clockwise puts it on the right.
    side = 1.0 if (not clockwise) == (radius > 0) else -1.0
    return (start + end) / 2.0 + side * h * left


def read_program(text, name="program"):
    """The pieces of a G-code program, for the subset the demo's programs use: G0-G3 with
    I/J (incremental, or absolute after G90.1) or R, G17, G20/G21, G90/G91, F, N, G61 and
    G64 [P]; the CAM preamble (S, T, M3-M9, G40, G49, G54-G59, G80, G94) is ignored,
    Z-only moves make the move before them stop, rapids before the first cut only
    position the tool, M2/M30 and a second % end the program."""
    pieces = []
    position = np.zeros(2)
    z = None
    absolute, arc_absolute, scale = True, False, 1.0
    motion, feed, corner, blend = None, None, "default", None
    percent = 0
    for number, raw in enumerate(text.splitlines(), start=1):
        if raw.strip() == "%":
            percent += 1
            if percent == 2:
                break
            continue
        words = [(letter.upper(), float(value)) for letter, value in _WORD.findall(_code(raw))]
        rest = _WORD.sub("", _code(raw)).strip()
        if rest:
            raise ProgramError(f"{name}:{number}: cannot read {rest!r}")
        axes, arc, values, end_program, this_motion = {}, {}, {}, False, None
        for letter, value in words:
            if letter == "G":
                code = round(value * 10)
                if code in (0, 10, 20, 30):
                    this_motion = code // 10
                elif code == 200:
                    scale = 25.4
                elif code == 210:
                    scale = 1.0
                elif code == 900:
                    absolute = True
                elif code == 910:
                    absolute = False
                elif code == 901:
                    arc_absolute = True
                elif code == 911:
                    arc_absolute = False
                elif code in (610, 611):
                    corner, blend = "stop", None
                elif code == 640:
                    values["G64"] = True
                elif code % 10 == 0 and code // 10 in _SKIPPED_G:
                    pass
                else:
                    raise ProgramError(f"{name}:{number}: G{value:g} is not read here")
            elif letter == "M":
                if value in (2, 30):
                    end_program = True
                elif value not in _SKIPPED_M:
                    raise ProgramError(f"{name}:{number}: M{value:g} is not read here")
            elif letter in "XY":
                axes[letter] = value * scale
            elif letter == "Z":
                values["Z"] = value * scale
            elif letter in "IJR":
                arc[letter] = value * scale
            elif letter in "FP":
                values[letter] = value
            elif letter in "NST":
                pass
            else:
                raise ProgramError(f"{name}:{number}: the word {letter} is not read here")
        if "F" in values:
            feed = values["F"] * scale / 60.0
        if values.get("G64"):
            p = values.get("P")
            corner, blend = ("blend", p * scale) if p else ("default", None)
        if this_motion is not None:
            motion = this_motion
        if "Z" in values and not axes:
            moves_z = z is None or values["Z"] != z
            z = values["Z"]
            if moves_z and pieces:
                pieces[-1].corner, pieces[-1].blend = "stop", None
        elif axes:
            if motion is None:
                raise ProgramError(f"{name}:{number}: axis words without a motion code")
            end = position.copy()
            for k, letter in enumerate("XY"):
                if letter in axes:
                    end[k] = axes[letter] if absolute else end[k] + axes[letter]
            if motion == 0 and not pieces:
                position = end  # positions the tool; the path starts at the first cut
            elif motion in (0, 1):
                if np.any(end != position):
                    pieces.append(Piece("line", position, end, number,
                                        None if motion == 0 else feed, corner, blend))
                position = end
            else:
                clockwise = motion == 2
                if "R" in arc:
                    centre = _arc_centre(position, end, arc["R"], clockwise)
                else:
                    offset = np.array([arc.get("I", 0.0), arc.get("J", 0.0)])
                    centre = offset if arc_absolute else position + offset
                radius = float(np.linalg.norm(position - centre))
                if abs(np.linalg.norm(end - centre) - radius) > max(2e-3, 1e-4 * radius):
                    raise ProgramError(f"{name}:{number}: the arc's end is not on its circle")
                a0 = math.atan2(*(position - centre)[::-1])
                a1 = math.atan2(*(end - centre)[::-1])
                turn = (a0 - a1) % (2 * math.pi) if clockwise else (a1 - a0) % (2 * math.pi)
                if turn < 1e-12:
                    turn = 2 * math.pi  # a full circle
                sweep = -turn if clockwise else turn
                pieces.append(Piece("arc", position, end, number, feed, corner, blend,
                                    centre=centre, radius=radius, start_angle=a0, sweep=sweep))
                position = end
        if end_program:
            break
    if not pieces:
        raise ProgramError(f"{name}: no move")
    for piece in pieces:
        block = re.search(r"^\s*N(\d+)", text.splitlines()[piece.line - 1], re.IGNORECASE)
        piece.label = f"N{block.group(1)}" if block else f"line {piece.line}"
    return pieces


def starts(pieces):
    """The path position (mm) of each piece's start, and the program's length last."""
    return np.concatenate([[0.0], np.cumsum([p.length for p in pieces])])


def joins(pieces):
    """Each join between consecutive pieces: (path position, kind), kind one of
    "tangent", "stop" (an exact stop, or a kink into or out of an arc, which the
    planner stops at) and "blend" (a kink between two lines under G64)."""
    at = starts(pieces)
    found = []
    for k in range(len(pieces) - 1):
        a, b = pieces[k], pieces[k + 1]
        cos = float(np.clip(a.tangent(1.0) @ b.tangent(0.0), -1.0, 1.0))
        if a.corner == "stop":
            kind = "stop"
        elif math.acos(cos) < TANGENT:
            kind = "tangent"
        elif a.kind == "line" and b.kind == "line":
            kind = "blend"
        else:
            kind = "stop"
        found.append((float(at[k + 1]), kind))
    return found


def distance(pieces, points):
    """The exact distance (mm) from each point to the programmed geometry, closed form per
    line and arc; returns (distance, path position of the foot point)."""
    points = np.asarray(points, dtype=float)
    best = np.full(len(points), np.inf)
    where = np.zeros(len(points))
    for piece, s0 in zip(pieces, starts(pieces)):
        if piece.kind == "line":
            d = piece.end - piece.start
            t = np.clip((points - piece.start) @ d / (d @ d), 0.0, 1.0)
            foot = piece.start + t[:, None] * d
            along = t * piece.length
        else:
            q = points - piece.centre
            turned = np.mod(math.copysign(1.0, piece.sweep)
                            * (np.arctan2(q[:, 1], q[:, 0]) - piece.start_angle), 2 * math.pi)
            near_start = (np.linalg.norm(points - piece.start, axis=1)
                          <= np.linalg.norm(points - piece.end, axis=1))
            u = np.where(turned <= abs(piece.sweep), turned / abs(piece.sweep),
                         np.where(near_start, 0.0, 1.0))
            phi = piece.start_angle + u * piece.sweep
            foot = piece.centre + piece.radius * np.column_stack([np.cos(phi), np.sin(phi)])
            along = u * piece.length
        d = np.linalg.norm(points - foot, axis=1)
        nearer = d < best
        best = np.where(nearer, d, best)
        where = np.where(nearer, s0 + along, where)
    return best, where


def _mirror_word(match):
    letter, value = match.group(1), match.group(2)
    if letter.upper() in "YJ":
        number = float(value)
        if number == 0.0:
            return f"{letter}{value}"
        return f"{letter}{value[1:]}" if value.startswith("-") else f"{letter}-{value.lstrip('+')}"
    if letter.upper() == "G" and float(value) in (2.0, 3.0):
        return f"{letter}{3 if float(value) == 2.0 else 2}"
    return match.group(0)


def mirror_program(text, name="program"):
    """The program mirrored about the x axis: Y and J negated, G2 and G3 swapped (R, I and
    the rest unchanged); comments are dropped and a header says what it is."""
    lines = []
    for raw in text.splitlines():
        code = _code(raw)
        if not code.strip() and raw.strip():
            continue  # a comment-only line: it described the original
        lines.append(_WORD.sub(_mirror_word, code).rstrip())
    header = [f"(mirror image of {name} about the X axis: Y -> -Y, J -> -J, G2 <-> G3)",
              "(written by contour_fmu.demo.part; it runs the other way round)"]
    at = 1 if lines and lines[0].strip() == "%" else 0
    return "\n".join(lines[:at] + header + lines[at:]) + "\n"


def point_at(pieces, s):
    """The point (mm) at path position `s` of the programmed part."""
    at = starts(pieces)
    k = min(int(np.searchsorted(at, s, side="right")) - 1, len(pieces) - 1)
    p, u = pieces[k], (s - at[k]) / pieces[k].length
    if p.kind == "line":
        return p.start + u * (p.end - p.start)
    phi = p.start_angle + u * p.sweep
    return p.centre + p.radius * np.array([math.cos(phi), math.sin(phi)])
