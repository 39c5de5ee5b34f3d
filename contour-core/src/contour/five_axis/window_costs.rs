//! The mapping's state costs c(k, j) for a run of consecutive segments at once
//! (docs/design/five-axis.md §5.2): the same numbers as [`segment_cost`], bit for bit, laid
//! out so that the compiler can compute two segments per instruction.
//!
//! The windowed decoder of a long run spends most of its time here: every sample costs
//! every segment of its window (64 by default). One segment's cost takes three square
//! roots and three divisions, which a scalar loop issues one at a time; here the
//! segments' starts, directions and squared lengths are kept once, column by column
//! (each direction is `b - a` as [`segment_cost`] computes it, so the same bits), and the
//! distances and the angle's two arguments are computed in loops without calls, which
//! vectorise. The angle itself is then taken per segment (`math::atan2_quadrant`: the
//! same bits as `math::atan2`).
//!
//! [`segment_cost`]: super::hmm::segment_cost

use super::hmm::{HmmParams, ReferencePolyline};
use crate::geometry::Vector;
use crate::math;

/// One polyline's segments, column by column: start `a`, direction `d = b - a`, `d·d`.
#[derive(Clone, Debug, Default)]
struct Columns {
    start: [Vec<f64>; 3],
    direction: [Vec<f64>; 3],
    length2: Vec<f64>,
}

impl Columns {
    fn new(points: &[Vector<3>]) -> Self {
        let mut columns = Columns::default();
        for w in points.windows(2) {
            let d = w[1] - w[0];
            for axis in 0..3 {
                columns.start[axis].push(w[0][axis]);
                columns.direction[axis].push(d[axis]);
            }
            columns.length2.push(d.dot(&d));
        }
        columns
    }

    /// The distance of `p` to segment `j` (as [`Columns::add_distances`] computes it).
    fn distance(&self, j: usize, p: &Vector<3>) -> f64 {
        let mut out = [0.0];
        self.add_distances(j, p, &mut out);
        out[0]
    }

    /// `out[s] += distance of p to segment first + s`, for every slot of `out`
    /// (hmm::segment_distance's operations in its order).
    fn add_distances(&self, first: usize, p: &Vector<3>, out: &mut [f64]) {
        let n = out.len();
        let [ax, ay, az] = self.start.each_ref().map(|c| &c[first..first + n]);
        let [dx, dy, dz] = self.direction.each_ref().map(|c| &c[first..first + n]);
        let dd = &self.length2[first..first + n];
        let (px, py, pz) = (p.x, p.y, p.z);
        for s in 0..n {
            let (qx, qy, qz) = (px - ax[s], py - ay[s], pz - az[s]);
            let along = qx * dx[s] + qy * dy[s] + qz * dz[s];
            let t = if dd[s] > 0.0 {
                (along / dd[s]).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let ox = ax[s] + dx[s] * t - px;
            let oy = ay[s] + dy[s] * t - py;
            let oz = az[s] + dz[s] * t - pz;
            out[s] += (ox * ox + oy * oy + oz * oz).sqrt();
        }
    }
}

/// The reference's segments as the windowed decoder costs them: O(segments) memory, 14
/// numbers a segment.
#[derive(Clone, Debug)]
pub struct SegmentTable {
    tips: Columns,
    seconds: Columns,
}

/// Work space of [`SegmentTable::costs`], kept by its caller so that no call allocates.
#[derive(Clone, Debug, Default)]
pub struct CostScratch {
    sine: Vec<f64>,
    cosine: Vec<f64>,
}

impl SegmentTable {
    /// The segments of `reference` (its tips' and its second points').
    pub fn new(reference: &ReferencePolyline) -> Self {
        SegmentTable {
            tips: Columns::new(&reference.tips),
            seconds: Columns::new(&reference.seconds),
        }
    }

    /// Number of segments.
    pub fn segments(&self) -> usize {
        self.tips.length2.len()
    }

    /// The tip's and the second point's distances to segment `j`, summed: c(k, j) without
    /// its angle term.
    pub fn distances(&self, j: usize, tip: &Vector<3>, second: &Vector<3>) -> f64 {
        self.tips.distance(j, tip) + self.seconds.distance(j, second)
    }

    /// `out[s]` = c(k, first + s) for every slot of `out`: the cost of segment `first + s`
    /// for the observation (`tip`, `second`) that moved by `motion`, exactly
    /// `segment_cost`'s. Panics when the segments run past the reference's end.
    pub fn costs(
        &self,
        params: &HmmParams,
        first: usize,
        observation: [&Vector<3>; 3],
        out: &mut [f64],
        scratch: &mut CostScratch,
    ) {
        let [tip, second, motion] = observation;
        let n = out.len();
        out.fill(0.0);
        // 0 + a is a (a ≥ 0 here): the sum's first term is the tip distance itself.
        self.tips.add_distances(first, tip, out);
        self.seconds.add_distances(first, second, out);
        let w = params.angle_weight;
        if *motion == Vector::<3>::zeros() {
            // No angle term while the tip stands still (w · 0, as segment_cost adds it).
            out.iter_mut().for_each(|c| *c += w * 0.0);
            return;
        }
        scratch.sine.resize(n, 0.0);
        scratch.cosine.resize(n, 0.0);
        let [dx, dy, dz] = self.tips.direction.each_ref().map(|c| &c[first..first + n]);
        let (mx, my, mz) = (motion.x, motion.y, motion.z);
        let (sine, cosine) = (&mut scratch.sine[..n], &mut scratch.cosine[..n]);
        for s in 0..n {
            // |motion × d| and motion · d, as nalgebra's cross and dot order them.
            let cx = my * dz[s] - mz * dy[s];
            let cy = mz * dx[s] - mx * dz[s];
            let cz = mx * dy[s] - my * dx[s];
            sine[s] = (cx * cx + cy * cy + cz * cz).sqrt();
            cosine[s] = mx * dx[s] + my * dy[s] + mz * dz[s];
        }
        for ((c, y), x) in out.iter_mut().zip(sine.iter()).zip(cosine.iter()) {
            *c += w * math::atan2_quadrant(*y, *x);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contour::five_axis::hmm::state_cost;
    use rand::rngs::StdRng;
    use rand::{RngExt, SeedableRng};

    type V3 = Vector<3>;

    fn point(rng: &mut StdRng, scale: f64) -> V3 {
        V3::new(
            rng.random_range(-scale..scale),
            rng.random_range(-scale..scale),
            rng.random_range(-scale..scale),
        )
    }

    /// Random polylines with repeated points (zero-length segments), points far off and
    /// near, motions zero, tiny and along a segment: every cost equals state_cost's bits.
    #[test]
    fn every_cost_is_the_scalar_cost_bit_for_bit() {
        let mut rng = StdRng::seed_from_u64(43);
        for case in 0..200 {
            let m = rng.random_range(2..40);
            let mut tips: Vec<V3> = (0..m).map(|_| point(&mut rng, 50.0)).collect();
            if case % 3 == 0 {
                let i = rng.random_range(1..m);
                tips[i] = tips[i - 1];
            }
            let axes: Vec<V3> = (0..m)
                .map(|_| crate::geometry::unit(&V3::new(0.2, -0.1, 1.0)).unwrap())
                .collect();
            let reference = ReferencePolyline::new(&tips, &axes, rng.random_range(0.0..150.0));
            let table = SegmentTable::new(&reference);
            assert_eq!(table.segments(), reference.segments());
            let params = HmmParams {
                max_skip: 1,
                angle_weight: [0.0, 0.1, 3.0][case % 3],
            };
            let tip = point(&mut rng, 60.0);
            let second = tip + point(&mut rng, 100.0);
            let motion = match case % 4 {
                0 => V3::zeros(),
                1 => point(&mut rng, 1e-6),
                2 => tips[1] - tips[0],
                _ => point(&mut rng, 2.0),
            };
            let first = rng.random_range(0..reference.segments());
            let n = rng.random_range(1..=reference.segments() - first);
            let mut out = vec![f64::NAN; n];
            let mut scratch = CostScratch::default();
            table.costs(
                &params,
                first,
                [&tip, &second, &motion],
                &mut out,
                &mut scratch,
            );
            for (s, c) in out.iter().enumerate() {
                let expected = state_cost(&reference, &params, first + s, &tip, &second, &motion);
                assert_eq!(
                    c.to_bits(),
                    expected.to_bits(),
                    "case {case}, segment {}",
                    first + s
                );
            }
        }
    }
}
