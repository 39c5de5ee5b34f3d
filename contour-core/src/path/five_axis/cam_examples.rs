//! Poses shaped like a five-axis CAM system's CL data, for tests and benchmarks: the tool
//! normal to a surface, through or beside vertical (docs/design/five-axis.md §5.3b). The
//! Python package writes the same shapes as CL files (`contour_fmu.demo.cam_paths`).

use crate::geometry::{self, Vector};
use crate::kinematics::Pose;
use crate::math;

/// A straight pass along x of `length` mm in `step` mm CL steps, the tool axis tilting
/// from +`tilt` to −`tilt` about y (rad), `beside` rad to the side of vertical (0: through
/// it).
pub fn tilting_pass(beside: f64, length: f64, step: f64, tilt: f64) -> Vec<Pose> {
    let n = (length / step).round().max(1.0) as usize;
    (0..=n)
        .map(|i| {
            let f = i as f64 / n as f64;
            let theta = tilt * (1.0 - 2.0 * f);
            Pose {
                tip: Vector::<3>::new(-length / 2.0 + length * f, 0.0, 0.0),
                axis: Vector::<3>::new(
                    math::sin(theta) * math::cos(beside),
                    math::sin(beside),
                    math::cos(theta) * math::cos(beside),
                ),
            }
        })
        .collect()
}

/// A finishing raster over a hemisphere of `radius` mm centred at the origin, the tool
/// normal to the surface: 2·`passes` + 1 passes along x, zigzag, `stepover` mm apart, the
/// middle one `offset` mm beside the apex, `step` mm between CL points, within `within`
/// rad of the apex.
pub fn dome_raster(
    radius: f64,
    stepover: f64,
    passes: i32,
    step: f64,
    within: f64,
    offset: f64,
) -> Vec<Pose> {
    let mut poses = Vec::new();
    for (k, j) in (-passes..=passes).enumerate() {
        let y = stepover * j as f64 + offset;
        let half = ((radius * math::sin(within)).powi(2) - y * y)
            .max(0.0)
            .sqrt();
        let steps = (2.0 * half / step).ceil().max(1.0) as usize;
        for i in 0..=steps {
            let f = i as f64 / steps as f64;
            let f = if k % 2 == 0 { f } else { 1.0 - f };
            let x = -half + 2.0 * half * f;
            let tip = Vector::<3>::new(x, y, (radius * radius - x * x - y * y).sqrt());
            poses.push(Pose {
                tip,
                axis: tip / radius,
            });
        }
    }
    poses
}

/// A unit vector tilted `tilt` rad from +Z toward the azimuth `azimuth` (rad from +X).
fn tilted(tilt: f64, azimuth: f64) -> Vector<3> {
    let (st, ct) = math::sincos(tilt);
    Vector::<3>::new(st * math::cos(azimuth), st * math::sin(azimuth), ct)
}

/// Two unit vectors that span the plane normal to the unit `n`.
fn plane_of(n: &Vector<3>) -> (Vector<3>, Vector<3>) {
    let helper = if n[2].abs() < 0.9 {
        Vector::<3>::z()
    } else {
        Vector::<3>::x()
    };
    let u = geometry::unit(&helper.cross(n)).expect("a helper off the normal");
    (u, n.cross(&u))
}

/// Writes CL records the way NX's CLSF post does.
struct ClsWriter {
    text: String,
    /// The last GOTO: tip and axis.
    at: Option<(Vector<3>, Vector<3>)>,
}

impl ClsWriter {
    fn goto(&mut self, tip: Vector<3>, axis: Vector<3>) {
        let axis = geometry::unit(&axis).expect("a tool axis");
        self.text += &format!(
            "GOTO/{:.4},{:.4},{:.4},{:.7},{:.7},{:.7}\n",
            tip[0], tip[1], tip[2], axis[0], axis[1], axis[2]
        );
        self.at = Some((tip, axis));
    }

    /// A feed move after a `FEDRAT` in mm/min.
    fn feed(&mut self, mmpm: f64) {
        self.text += &format!("PAINT/COLOR,211\nFEDRAT/MMPM,{mmpm:.4}\n");
    }

    fn rapid(&mut self, tip: Vector<3>, axis: Vector<3>) {
        self.text += "PAINT/COLOR,186\nRAPID\n";
        self.goto(tip, axis);
    }

    /// An arc about `axis` (counter-clockwise about it) from the last tip to `end`.
    fn circle(&mut self, centre: Vector<3>, axis: Vector<3>, radius: f64, end: Vector<3>) {
        let (_, tool) = self.at.expect("an arc starts where the tool is");
        self.text += &format!(
            "CIRCLE/{:.4},{:.4},{:.4},{:.7},{:.7},{:.7},{radius:.4},0.0100,0.5000,20.0000,0.0000\n",
            centre[0], centre[1], centre[2], axis[0], axis[1], axis[2]
        );
        self.goto(end, tool);
    }

    /// An operation's header, a rapid to `clearance` mm above its first pose along that
    /// pose's axis and down to it at `mmpm`; `body` writes the rest.
    fn operation(
        &mut self,
        name: &str,
        first: (Vector<3>, Vector<3>),
        mmpm: f64,
        body: impl FnOnce(&mut Self),
    ) {
        let clearance = 30.0;
        self.text += &format!(
            "TOOL PATH/{name},TOOL,BALL_MILL_6\nTLDATA/MILL,6.0000,3.0000,50.0000,0.0000,0.0000\n\
             MSYS/0.0000,0.0000,0.0000,1.0000000,0.0000000,0.0000000,0.0000000,1.0000000,0.0000000\n\
             $$ centerline data\nPAINT/PATH\nPAINT/SPEED,10\nLOAD/TOOL,1,ADJUST,1\n\
             SPINDL/RPM,10000,CLW\n"
        );
        let (tip, axis) = first;
        self.rapid(tip + axis * clearance, axis);
        self.feed(mmpm);
        self.goto(tip, axis);
        body(self);
        let (tip, axis) = self.at.expect("an operation moves");
        self.rapid(tip + axis * clearance, axis);
        self.text += "PAINT/SPEED,10\nPAINT/TOOL,NOMORE\nEND-OF-PATH\n";
    }
}

/// A raster of `passes` zigzag passes of `length` mm, `stepover` apart, CL points `step`
/// apart, on the plane through `origin` normal to the tool `axis` (3+2 machining).
fn raster(
    origin: Vector<3>,
    axis: Vector<3>,
    length: f64,
    passes: usize,
    stepover: f64,
    step: f64,
) -> Vec<Vector<3>> {
    let (u, v) = plane_of(&axis);
    let n = (length / step).round() as usize;
    let mut tips = Vec::new();
    for p in 0..passes {
        for i in 0..=n {
            let i = if p % 2 == 0 { i } else { n - i };
            let a = -length / 2.0 + length * i as f64 / n as f64;
            let b = stepover * (p as f64 - (passes - 1) as f64 / 2.0);
            tips.push(origin + u * a + v * b);
        }
    }
    tips
}

/// A multi-operation part as NX writes its CLSF (inspired by the 15-operation file the
/// CL-data issue was found with; written here, in mm): an information listing's header,
/// then fifteen operations, each with its `TOOL PATH`, `TLDATA`, `MSYS`, `PAINT`,
/// `SPINDL`, `FEDRAT` and `END-OF-PATH` records and rapids in and out along the tool
/// axis: facing and contouring with a vertical tool and `CIRCLE` corners, 3+2 rasters
/// tilted 30° to 90°, a pocket circle on a 45° face, a swarf pass tilting 0° to 90°, a
/// finishing raster over a dome's apex (through vertical), a pass beside vertical with
/// the azimuth swinging, a tilted spiral turning C twice, holes along a 45° axis, small
/// corner radii, a flank pass round the part at 75°. About 10 500 `GOTO`s.
pub fn nx_multi_operation_cls() -> String {
    let mut w = ClsWriter {
        text: String::from(
            "==============================================================\n\
             Information listing created by :  cam\n\
             Date                           :  04.12.2026 09:12:44\n\
             Current work part              :  bracket_5x.prt\n\
             Node name                      :  cam-ws-04\n\
             ==============================================================\n\n",
        ),
        at: None,
    };
    let z = Vector::<3>::z();
    let at = |x: f64, y: f64, zz: f64| Vector::<3>::new(x, y, zz);

    // OP010: facing, the tool vertical.
    let face = raster(at(0.0, 0.0, 0.0), z, 100.0, 21, 4.0, 2.0);
    w.operation("OP010_FACE", (face[0], z), 1500.0, |w| {
        for &t in &face[1..] {
            w.goto(t, z);
        }
    });

    // OP020: a rounded rectangle at four depths, CIRCLE corners.
    let contour = |w: &mut ClsWriter, depth: f64, r: f64| {
        let (hx, hy) = (40.0, 30.0);
        let corners = [
            (
                at(hx - r, -hy, depth),
                at(hx - r, -hy + r, depth),
                at(hx, -hy + r, depth),
            ),
            (
                at(hx, hy - r, depth),
                at(hx - r, hy - r, depth),
                at(hx - r, hy, depth),
            ),
            (
                at(-hx + r, hy, depth),
                at(-hx + r, hy - r, depth),
                at(-hx, hy - r, depth),
            ),
            (
                at(-hx, -hy + r, depth),
                at(-hx + r, -hy + r, depth),
                at(-hx + r, -hy, depth),
            ),
        ];
        for (start, centre, end) in corners {
            let (from, _) = w.at.unwrap();
            let n = (geometry::norm(&(start - from)) / 2.0).ceil().max(1.0) as usize;
            for i in 1..=n {
                w.goto(from + (start - from) * (i as f64 / n as f64), z);
            }
            w.circle(centre, z, r, end);
        }
        let (from, _) = w.at.unwrap();
        let start = at(-hx + r, -hy, depth);
        if geometry::norm(&(start - from)) > 0.0 {
            w.goto(start, z);
        }
    };
    let contour_start = at(-32.0, -30.0, -2.0);
    w.operation("OP020_CONTOUR", (contour_start, z), 900.0, |w| {
        for depth in [-2.0, -4.0, -6.0, -8.0] {
            w.goto(at(-32.0, -30.0, depth), z);
            contour(w, depth, 8.0);
        }
    });

    // OP030–OP060: 3+2 rasters on faces tilted 30°, 45°, 60° and 90°.
    for (k, (tilt, azimuth)) in [
        (30.0f64, 0.0f64),
        (45.0, 90.0),
        (60.0, 180.0),
        (90.0, 270.0),
    ]
    .into_iter()
    .enumerate()
    {
        let axis = tilted(tilt.to_radians(), azimuth.to_radians());
        let origin = axis * 45.0 - z * 20.0;
        let tips = raster(origin, axis, 40.0, 11, 3.0, 1.0);
        w.operation(
            &format!("OP0{}0_TILT_{tilt:.0}", k + 3),
            (tips[0], axis),
            1200.0,
            |w| {
                for &t in &tips[1..] {
                    w.goto(t, axis);
                }
                if tilt == 45.0 {
                    // A pocket's circle on the face, full turn.
                    let (u, _) = plane_of(&axis);
                    let (end, _) = w.at.unwrap();
                    w.circle(end - u * 6.0, axis, 6.0, end);
                }
            },
        );
    }

    // OP070: a swarf pass tilting from vertical to 90° along a wavy wall, three levels.
    let swarf = |level: usize, i: usize, n: usize| {
        let f = i as f64 / n as f64;
        let f = if level.is_multiple_of(2) { f } else { 1.0 - f };
        let x = -60.0 + 120.0 * f;
        let tip = at(
            x,
            20.0 + 5.0 * math::sin(x / 12.0),
            -4.0 * level as f64 - 2.0,
        );
        (
            tip,
            tilted(
                f * std::f64::consts::FRAC_PI_2,
                -std::f64::consts::FRAC_PI_2,
            ),
        )
    };
    w.operation("OP070_SWARF", swarf(0, 0, 240), 600.0, |w| {
        for level in 0..3 {
            for i in 0..=240 {
                let (tip, axis) = swarf(level, i, 240);
                w.goto(tip, axis);
            }
        }
    });

    // OP080: finishing over a dome's apex, the tool normal to it.
    let dome: Vec<Pose> = dome_raster(40.0, 2.5, 12, 1.0, 1.0, 0.0)
        .into_iter()
        .map(|p| Pose {
            tip: p.tip - z * 40.0,
            axis: p.axis,
        })
        .collect();
    w.operation("OP080_DOME", (dome[0].tip, dome[0].axis), 1800.0, |w| {
        for p in &dome[1..] {
            w.goto(p.tip, p.axis);
        }
    });

    // OP090: a pass beside vertical (0.3°–1.9°) with the azimuth swinging ±140°.
    let beside = |i: usize| {
        let x = -50.0 + 0.1 * i as f64;
        let tilt = (0.3 + 1.6 * 0.5 * (1.0 + math::sin(x / 3.0))).to_radians();
        (at(x, -10.0, 1.0), tilted(tilt, 2.45 * math::sin(x / 5.0)))
    };
    w.operation("OP090_NEAR_VERTICAL", beside(0), 1000.0, |w| {
        for i in 1..=1000 {
            let (tip, axis) = beside(i);
            w.goto(tip, axis);
        }
    });

    // OP100: a spiral down a boss, the axis 20° off vertical leaning outward: C turns twice.
    let spiral = |i: usize| {
        let angle = (i as f64 * 0.5).to_radians();
        let tip = at(
            30.0 * math::cos(angle),
            30.0 * math::sin(angle),
            -0.005 * i as f64,
        );
        (tip, tilted(20f64.to_radians(), angle))
    };
    w.operation("OP100_SPIRAL", spiral(0), 1500.0, |w| {
        for i in 1..=1440 {
            let (tip, axis) = spiral(i);
            w.goto(tip, axis);
        }
    });

    // OP110: eight holes along a 45° axis: down at the feed, out at rapid.
    let hole_axis = tilted(45f64.to_radians(), 45f64.to_radians());
    let hole = |k: usize| at(-35.0 + 10.0 * k as f64, 35.0, -10.0);
    w.operation(
        "OP110_HOLES",
        (hole(0) + hole_axis * 2.0, hole_axis),
        300.0,
        |w| {
            for k in 0..8 {
                if k > 0 {
                    w.rapid(hole(k) + hole_axis * 2.0, hole_axis);
                    w.feed(300.0);
                }
                w.goto(hole(k) - hole_axis * 8.0, hole_axis);
                w.rapid(hole(k) + hole_axis * 2.0, hole_axis);
            }
        },
    );

    // OP120: a raster on a vertical face at azimuth 45°.
    let side = tilted(std::f64::consts::FRAC_PI_2, 45f64.to_radians());
    let wall = raster(side * 50.0 - z * 15.0, side, 30.0, 9, 2.0, 0.5);
    w.operation("OP120_WALL", (wall[0], side), 1000.0, |w| {
        for &t in &wall[1..] {
            w.goto(t, side);
        }
    });

    // OP130: contours with small corner radii.
    w.operation("OP130_CORNERS", (at(-38.0, -30.0, -10.0), z), 600.0, |w| {
        for (depth, r) in [(-10.0, 2.0), (-11.0, 1.0), (-12.0, 0.5)] {
            w.goto(at(-40.0 + r, -30.0, depth), z);
            contour(w, depth, r);
        }
    });

    // OP140: a flank pass round the part at 75°, the axis leaning outward: C turns once.
    let flank = |i: usize| {
        let angle = (i as f64 * 0.5).to_radians();
        let tip = at(45.0 * math::cos(angle), 45.0 * math::sin(angle), -25.0);
        (
            tip,
            tilted(75f64.to_radians(), angle + std::f64::consts::PI),
        )
    };
    w.operation("OP140_FLANK", flank(0), 800.0, |w| {
        for i in 1..=720 {
            let (tip, axis) = flank(i);
            w.goto(tip, axis);
        }
    });

    // OP150: the last facing pass, finer.
    let last = raster(at(0.0, 0.0, 0.5), z, 90.0, 23, 3.0, 1.5);
    w.operation("OP150_FACE_FINISH", (last[0], z), 2000.0, |w| {
        for &t in &last[1..] {
            w.goto(t, z);
        }
    });
    w.text
}

/// A pass near vertical as NX writes it (inch, `MSYS`, `FEDRAT/IPM` at 40 in/min): `n`
/// GOTOs `step` inches apart along x, the tool axis tilted between 0.3° and `max_tilt`
/// degrees, its azimuth `swing`·sin(x / `period`) (rad); the pass crosses the default
/// pole cone (2°) again and again.
pub fn nx_near_pole_pass(n: usize, step: f64, max_tilt: f64, swing: f64, period: f64) -> String {
    let mut text = String::from(
        "TOOL PATH/NEAR_POLE,TOOL,BALL_125\nTLDATA/MILL,0.1250,0.0625,2.0000,0.0000,0.0000\n\
         MSYS/0.0000,0.0000,0.0000,1.0000000,0.0000000,0.0000000,0.0000000,1.0000000,0.0000000\n\
         PAINT/PATH\nFEDRAT/IPM,40.0000\n",
    );
    for i in 0..n {
        let x = i as f64 * step;
        let tilt = (0.3 + (max_tilt - 0.3) * 0.5 * (1.0 + math::sin(x / 0.12))).to_radians();
        let azimuth = swing * math::sin(x / period);
        let (st, ct) = math::sincos(tilt);
        text += &format!(
            "GOTO/{x:.4},{:.4},0.0000,{:.7},{:.7},{:.7}\n",
            0.01 * math::sin(x / 0.3),
            st * math::cos(azimuth),
            st * math::sin(azimuth),
            ct
        );
    }
    text + "END-OF-PATH\n"
}
