//! The drilling cycles of G-code (docs/design/two-axis.md §4.7), G73, G74, G81–G85 and
//! G89 in the XY plane, as LinuxCNC runs them: each hole is the moves the machine makes
//! (rapid up to R if below it, rapid over the hole, rapid down to R, the cycle's feed
//! moves in Z, a dwell, the retract at rapid to where Z began (G98) or to R (G99)), so a
//! machine with Z follows them and one without stands for their time.

use super::Motion;
use crate::geometry::{Vector, Vector2};

/// How far a peck backs off: G83's rapid down stops this far above the last bottom, and
/// G73 retracts by it to break the chip (LinuxCNC's 0.010 in), mm.
pub const PECK_CLEARANCE: f64 = 0.254;

/// The most pecks one hole may take (a Q far smaller than the hole is a wrong program,
/// not millions of moves).
pub const MAX_PECKS: f64 = 10_000.0;

/// The cycles read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CycleKind {
    /// G73: feed down in pecks of Q, backing off [`PECK_CLEARANCE`] between them.
    ChipBreak,
    /// G81: feed to the bottom.
    Drill,
    /// G82: feed to the bottom and dwell P.
    DrillDwell,
    /// G83: feed down in pecks of Q, out to R between them.
    Peck,
    /// G85: feed to the bottom and back to R.
    Bore,
    /// G89: feed to the bottom, dwell P, feed back to R.
    BoreDwell,
    /// G84 (G74 left-handed): tap, feeding to the bottom, dwelling P and feeding back to R
    /// as the spindle reverses (which the axes do not see).
    Tap,
}

impl CycleKind {
    /// The cycle of G`code`, if it is one.
    pub fn from_code(code: u32) -> Option<Self> {
        Some(match code {
            73 => CycleKind::ChipBreak,
            81 => CycleKind::Drill,
            82 => CycleKind::DrillDwell,
            83 => CycleKind::Peck,
            85 => CycleKind::Bore,
            89 => CycleKind::BoreDwell,
            74 | 84 => CycleKind::Tap,
            _ => return None,
        })
    }

    fn pecks(self) -> bool {
        matches!(self, CycleKind::ChipBreak | CycleKind::Peck)
    }
}

/// A cycle in force: its kind and its sticky words (they stay from block to block until
/// G80 or another motion code), all in mm and seconds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cycle {
    pub kind: CycleKind,
    /// Z when the cycles began: where G98 retracts to.
    start_z: f64,
    /// Z: the hole's bottom.
    depth: Option<f64>,
    /// R: the plane the feed starts from and G99 retracts to.
    retract: Option<f64>,
    /// P: the dwell at the bottom of G82 and G89, s.
    dwell: f64,
    /// Q: the peck, mm.
    peck: Option<f64>,
}

/// One move of a hole.
#[derive(Clone, Debug, PartialEq)]
pub struct Step {
    /// A line, or the dwell.
    pub motion: Motion,
    /// At rapid or at the feed in force.
    pub speed: StepSpeed,
    /// Where the tip is after it.
    pub end: Vector<3>,
}

/// How fast a step goes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StepSpeed {
    Rapid,
    Feed,
}

/// A value of a word with the column it stands in.
type Placed = Option<(f64, usize)>;

impl Cycle {
    /// A cycle that begins with the tip at height `start_z`.
    pub fn new(kind: CycleKind, start_z: f64) -> Self {
        Cycle {
            kind,
            start_z,
            depth: None,
            retract: None,
            dwell: 0.0,
            peck: None,
        }
    }

    /// The same cycle's words under another kind (a series of cycles keeps its start).
    pub fn with_kind(self, kind: CycleKind) -> Self {
        Cycle { kind, ..self }
    }

    /// Takes a block's Z, R, P (s) and Q; the error gives the word's column.
    pub fn update(
        &mut self,
        depth: Placed,
        retract: Placed,
        dwell: Placed,
        peck: Placed,
    ) -> Result<(), (usize, String)> {
        let finite = |w: Placed, what: &str| match w {
            Some((v, column)) if !v.is_finite() => Err((column, format!("{what} must be finite"))),
            _ => Ok(w.map(|(v, _)| v)),
        };
        if let Some(z) = finite(depth, "a cycle's Z")? {
            self.depth = Some(z);
        }
        if let Some(r) = finite(retract, "a cycle's R")? {
            self.retract = Some(r);
        }
        if let Some((p, column)) = dwell {
            if !(p.is_finite() && p >= 0.0) {
                return Err((column, "a cycle's dwell P must be >= 0".into()));
            }
            self.dwell = p;
        }
        if let Some((q, column)) = peck {
            if !(q.is_finite() && q > 0.0) {
                return Err((column, "a cycle's peck Q must be > 0".into()));
            }
            self.peck = Some(q);
        }
        Ok(())
    }

    /// The moves of the hole at `at` with the tip at `from`; G98 when `retract_to_start`.
    pub fn hole(
        &self,
        from: Vector<3>,
        at: Vector2,
        retract_to_start: bool,
    ) -> Result<Vec<Step>, String> {
        let Some(r) = self.retract else {
            return Err("a drilling cycle needs R (the plane its feed starts from)".into());
        };
        let Some(depth) = self.depth else {
            return Err("a drilling cycle needs Z (the hole's bottom)".into());
        };
        if depth > r {
            return Err(format!(
                "the hole's bottom Z {depth} mm is above its R plane {r} mm"
            ));
        }
        let (x, y) = (at[0], at[1]);
        let mut hole = Hole {
            steps: Vec::new(),
            tip: from,
        };
        if from[2] < r {
            hole.go(from[0], from[1], r, StepSpeed::Rapid);
        }
        hole.go(x, y, from[2].max(r), StepSpeed::Rapid);
        hole.go(x, y, r, StepSpeed::Rapid);
        match (self.kind.pecks(), self.peck) {
            (true, None) => return Err("a peck cycle (G73, G83) needs Q (the peck)".into()),
            (true, Some(q)) => {
                if (r - depth) / q > MAX_PECKS {
                    return Err(format!(
                        "Q = {q} mm makes more than {MAX_PECKS} pecks of a hole {} mm deep",
                        r - depth
                    ));
                }
                let mut bottom = r;
                loop {
                    let next = (bottom - q).max(depth);
                    hole.go(x, y, next, StepSpeed::Feed);
                    if next <= depth {
                        break;
                    }
                    if self.kind == CycleKind::Peck {
                        hole.go(x, y, r, StepSpeed::Rapid);
                    }
                    hole.go(x, y, (next + PECK_CLEARANCE).min(r), StepSpeed::Rapid);
                    bottom = next;
                }
            }
            (false, _) => hole.go(x, y, depth, StepSpeed::Feed),
        }
        if matches!(
            self.kind,
            CycleKind::DrillDwell | CycleKind::BoreDwell | CycleKind::Tap
        ) {
            hole.steps.push(Step {
                motion: Motion::Dwell(self.dwell),
                speed: StepSpeed::Rapid,
                end: hole.tip,
            });
        }
        if matches!(
            self.kind,
            CycleKind::Bore | CycleKind::BoreDwell | CycleKind::Tap
        ) {
            hole.go(x, y, r, StepSpeed::Feed);
        }
        let top = if retract_to_start {
            self.start_z.max(r)
        } else {
            r
        };
        hole.go(x, y, top, StepSpeed::Rapid);
        Ok(hole.steps)
    }
}

/// The moves of one hole so far, and where they leave the tip.
struct Hole {
    steps: Vec<Step>,
    tip: Vector<3>,
}

impl Hole {
    /// A line to (x, y, z), unless the tip is there.
    fn go(&mut self, x: f64, y: f64, z: f64, speed: StepSpeed) {
        let end = Vector::<3>::new(x, y, z);
        if end != self.tip {
            self.steps.push(Step {
                motion: Motion::Line,
                speed,
                end,
            });
            self.tip = end;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn zs(steps: &[Step]) -> Vec<(f64, StepSpeed)> {
        steps
            .iter()
            .filter(|s| s.motion == Motion::Line)
            .map(|s| (s.end[2], s.speed))
            .collect()
    }

    #[test]
    fn a_peck_cycle_backs_out_to_r_and_returns_above_its_last_bottom() {
        use StepSpeed::{Feed, Rapid};
        let mut c = Cycle::new(CycleKind::Peck, 10.0);
        c.update(Some((-2.5, 1)), Some((1.0, 1)), None, Some((1.5, 1)))
            .unwrap();
        let steps = c
            .hole(
                Vector::<3>::new(0.0, 0.0, 10.0),
                Vector2::new(5.0, 0.0),
                true,
            )
            .unwrap();
        // Over the hole at 10, down to R, pecks to −0.5, −2, −2.5, back up to 10.
        let want = [
            (10.0, Rapid),
            (1.0, Rapid),
            (-0.5, Feed),
            (1.0, Rapid),
            (-0.5 + PECK_CLEARANCE, Rapid),
            (-2.0, Feed),
            (1.0, Rapid),
            (-2.0 + PECK_CLEARANCE, Rapid),
            (-2.5, Feed),
            (10.0, Rapid),
        ];
        assert_eq!(zs(&steps), want);
        assert_eq!(steps[0].end, Vector::<3>::new(5.0, 0.0, 10.0));
        // G99 and G82: out to R after the dwell.
        let mut d = Cycle::new(CycleKind::DrillDwell, 10.0);
        d.update(Some((-1.0, 1)), Some((2.0, 1)), Some((0.5, 1)), None)
            .unwrap();
        let steps = d
            .hole(
                Vector::<3>::new(5.0, 0.0, 2.0),
                Vector2::new(5.0, 5.0),
                false,
            )
            .unwrap();
        assert_eq!(zs(&steps), [(2.0, Rapid), (-1.0, Feed), (2.0, Rapid)]);
        assert!(steps.iter().any(|s| s.motion == Motion::Dwell(0.5)));
    }

    #[test]
    fn cycles_without_their_words_or_with_absurd_ones_are_refused() {
        let from = Vector::<3>::zeros();
        let c = Cycle::new(CycleKind::Drill, 5.0);
        assert!(c
            .hole(from, Vector2::zeros(), true)
            .unwrap_err()
            .contains("needs R"));
        let mut c = Cycle::new(CycleKind::Peck, 5.0);
        c.update(Some((-1.0, 1)), Some((1.0, 1)), None, None)
            .unwrap();
        assert!(c
            .hole(from, Vector2::zeros(), true)
            .unwrap_err()
            .contains("needs Q"));
        c.update(None, None, None, Some((1e-6, 1))).unwrap();
        assert!(c
            .hole(from, Vector2::zeros(), true)
            .unwrap_err()
            .contains("pecks"));
        assert!(c.update(None, None, None, Some((0.0, 3))).is_err());
        assert!(c.update(None, None, Some((-1.0, 4)), None).is_err());
        c.update(Some((2.0, 1)), None, None, None).unwrap();
        assert!(c
            .hole(from, Vector2::zeros(), true)
            .unwrap_err()
            .contains("above"));
    }
}
