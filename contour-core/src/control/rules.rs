//! Linguistic terms and the three classical fuzzy-PID rule tables of docs/design/two-axis.md §4.3.
//!
//! The tables are plain data so the engine, the scikit-fuzzy cross-check and any future
//! tuning code all read the same source; rows are indexed by the contour-error input E
//! and columns by its change EC, both in the order NB … PB.

use serde::{Deserialize, Serialize};

/// One of the seven fuzzy sets; its discriminant is the index of the set, and the set is
/// centred at `index − 3` on the normalised universe [−3, 3].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[repr(u8)]
pub enum Term {
    /// Negative big, centred at −3 (flat shoulder below −3).
    NB = 0,
    /// Negative medium, centred at −2.
    NM = 1,
    /// Negative small, centred at −1.
    NS = 2,
    /// Zero, centred at 0.
    ZO = 3,
    /// Positive small, centred at 1.
    PS = 4,
    /// Positive medium, centred at 2.
    PM = 5,
    /// Positive big, centred at 3 (flat shoulder above 3).
    PB = 6,
}

impl Term {
    /// All terms in universe order.
    pub const ALL: [Term; 7] = [
        Term::NB,
        Term::NM,
        Term::NS,
        Term::ZO,
        Term::PS,
        Term::PM,
        Term::PB,
    ];

    /// Position of the set in [`Term::ALL`] (0 for NB … 6 for PB).
    pub const fn index(self) -> usize {
        self as usize
    }

    /// Centre of the triangular set on the normalised universe.
    pub const fn centre(self) -> f64 {
        self as u8 as f64 - 3.0
    }

    /// The two-letter name used in docs/design/two-axis.md §4.3 (and by the scikit-fuzzy reference).
    pub const fn name(self) -> &'static str {
        match self {
            Term::NB => "NB",
            Term::NM => "NM",
            Term::NS => "NS",
            Term::ZO => "ZO",
            Term::PS => "PS",
            Term::PM => "PM",
            Term::PB => "PB",
        }
    }
}

/// A rule table: `table[e][ec]` is the output set fired by "E is e AND EC is ec".
pub type RuleTable = [[Term; 7]; 7];

use Term::{NB, NM, NS, PB, PM, PS, ZO};

/// ΔKp′ rules: a large error of one sign calls for more proportional action (docs/design/two-axis.md §4.3).
pub const KP_RULES: RuleTable = [
    [PB, PB, PM, PM, PS, ZO, ZO],
    [PB, PB, PM, PS, PS, ZO, NS],
    [PM, PM, PM, PS, ZO, NS, NS],
    [PM, PM, PS, ZO, NS, NM, NM],
    [PS, PS, ZO, NS, NS, NM, NM],
    [PS, ZO, NS, NM, NM, NM, NB],
    [ZO, ZO, NM, NM, NM, NB, NB],
];

/// ΔKi′ rules (docs/design/two-axis.md §4.3).
pub const KI_RULES: RuleTable = [
    [NB, NB, NM, NM, NS, ZO, ZO],
    [NB, NB, NM, NS, NS, ZO, ZO],
    [NB, NM, NS, NS, ZO, PS, PS],
    [NM, NM, NS, ZO, PS, PM, PM],
    [NM, NS, ZO, PS, PS, PM, PB],
    [ZO, ZO, PS, PS, PM, PB, PB],
    [ZO, ZO, PS, PM, PM, PB, PB],
];

/// ΔKd′ rules (docs/design/two-axis.md §4.3).
pub const KD_RULES: RuleTable = [
    [PS, NS, NB, NB, NB, NM, PS],
    [PS, NS, NB, NM, NM, NS, ZO],
    [ZO, NS, NM, NM, NS, NS, ZO],
    [ZO, NS, NS, NS, NS, NS, ZO],
    [ZO, ZO, ZO, ZO, ZO, ZO, ZO],
    [PB, NS, PS, PS, PS, PS, PB],
    [PB, PM, PM, PM, PS, PS, PB],
];

/// The three tables in output order (ΔKp′, ΔKi′, ΔKd′).
pub const FUZZY_PID_RULES: [RuleTable; 3] = [KP_RULES, KI_RULES, KD_RULES];

#[cfg(test)]
mod tests {
    use super::*;

    /// Spot checks against docs/design/two-axis.md §4.3 written out independently of the tables' layout.
    #[test]
    fn tables_match_design_spot_checks() {
        // (table, E, EC, expected)
        let cases = [
            (KP_RULES, NB, NB, PB),
            (KP_RULES, ZO, ZO, ZO),
            (KP_RULES, PM, PB, NB),
            (KP_RULES, NM, PB, NS),
            (KI_RULES, PS, PB, PB),
            (KI_RULES, NS, PS, ZO),
            (KI_RULES, NS, PM, PS),
            (KI_RULES, PB, ZO, PM),
            (KD_RULES, NB, PB, PS),
            (KD_RULES, PM, NM, NS),
            (KD_RULES, PB, NM, PM),
            (KD_RULES, NB, PM, NM),
        ];
        for (table, e, ec, want) in cases {
            assert_eq!(table[e.index()][ec.index()], want, "{e:?} {ec:?}");
        }
    }

    #[test]
    fn term_geometry() {
        for (k, t) in Term::ALL.iter().enumerate() {
            assert_eq!(t.index(), k);
            assert_eq!(t.centre(), k as f64 - 3.0);
        }
        assert_eq!(Term::PM.name(), "PM");
    }
}
