//! One bone's ribbon separation surface (paper SMEAR Eqs. 3–6), precomputed per bone and frame.

use glam::Vec3;

use crate::options::DEFAULT_LERP_ANGLE;

/// Points per block of [`eval_batch`] (two SSE registers; 4 costs more overhead).
const BATCH_LANES: usize = 8;

/// The block of [`BATCH_LANES`] entries of `c` starting at `s`.
#[inline(always)]
fn lanes_mut(c: &mut [f32], s: usize) -> &mut [f32; BATCH_LANES] {
    (&mut c[s..s + BATCH_LANES])
        .try_into()
        .expect("BATCH_LANES entries")
}

/// Smoothstep S(x) = 3x² − 2x³ on x clamped to [0, 1] (SMEAR Eq. 3).
#[inline]
pub fn smoothstep(x: f32) -> f32 {
    let x = x.clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

/// `(sin x, cos x)` for x ∈ [0, π] by Taylor polynomials around π/2 (|error| < 2e-7, a few
/// times faster than `f32::sin_cos`, which dominates SMEAR Eq. 4 otherwise).
#[inline]
pub(crate) fn sin_cos_0_pi(x: f32) -> (f32, f32) {
    let y = x - std::f32::consts::FRAC_PI_2;
    let y2 = y * y;
    let cos_y = 1.0
        + y2 * (-1.0 / 2.0
            + y2 * (1.0 / 24.0
                + y2 * (-1.0 / 720.0
                    + y2 * (1.0 / 40_320.0
                        + y2 * (-1.0 / 3_628_800.0 + y2 * (1.0 / 479_001_600.0))))));
    let sin_y = y
        * (1.0
            + y2 * (-1.0 / 6.0
                + y2 * (1.0 / 120.0
                    + y2 * (-1.0 / 5040.0 + y2 * (1.0 / 362_880.0 + y2 * (-1.0 / 39_916_800.0))))));
    (cos_y, -sin_y)
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Interp {
    /// SMEAR Eq. 4: v̂(u) = cos(uω)·P + sin(uω)·Q with P = v̂_r and Q the unit vector orthogonal to
    /// v̂_r in the plane of v̂_r, v̂_t (equal to SMEAR Eq. 4's slerp).
    Slerp,
    /// Renormalized lerp (1 − u)·P + u·Q, P = v̂_r, Q = v̂_t, when ω < 0.1 rad.
    Lerp,
    /// Both joints still: the bone contributes 0.
    Still,
}

/// A bone's ribbon at one frame: everything of SMEAR Eqs. 3–6 that does not depend on the vertex.
///
/// The interpolated direction is written v(u) = α(u)·P + β(u)·Q, so that the ribbon normal
/// n(u) = v − (v·b̂)b̂ (SMEAR Eq. 5), the offset δ̃ = (p − c_r)·n̂ (SMEAR Eq. 6) and the collinear weight
/// w_coll = 1 − (v̂·b̂)² reduce to a few dot products per vertex.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Ribbon {
    root: Vec3,
    axis: Vec3,
    inv_len: f32,
    p: Vec3,
    q: Vec3,
    pb: f32,
    qb: f32,
    pp: f32,
    pq: f32,
    qq: f32,
    omega: f32,
    interp: Interp,
    /// Ribbon normal n̂ and w_coll at u = 0 and u = 1, for points beyond the bone's ends
    /// (where the smoothstep clamps and SMEAR Eq. 6 reduces to a dot product).
    n0: Vec3,
    coll0: f32,
    n1: Vec3,
    coll1: f32,
}

/// n̂ and w_coll of SMEAR Eq. 5–6 for a direction `v` (any length): zero where v ∥ axis.
fn end_normal(v: Vec3, axis: Vec3) -> (Vec3, f32) {
    let vv = v.dot(v);
    let vb = v.dot(axis);
    let nn = vv - vb * vb;
    if nn > 1e-12 * vv {
        ((v - vb * axis) / nn.sqrt(), nn / vv)
    } else {
        (Vec3::ZERO, 0.0)
    }
}

/// SMEAR Eqs. 3–6 at one point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct RibbonSample {
    /// Parameter u along the bone (SMEAR Eq. 3).
    pub(crate) u: f32,
    /// Unnormalized offset δ̃ = (p − c_r)·n̂(u) (SMEAR Eq. 6/8).
    pub(crate) raw: f32,
    /// Collinear weight w_coll(u) = 1 − (v̂(u)·b̂)².
    pub(crate) coll: f32,
}

impl Ribbon {
    /// The ribbon of the bone `root → tip` whose joints move with `v_root`, `v_tip`.
    ///
    /// # Returns
    /// `None` for a zero-length bone (`|tip − root| <= zero_length`), which is skipped. A joint
    /// moving no faster than `still` takes the other joint's direction; with both still the
    /// ribbon gives 0 everywhere (SPEC.md).
    pub(crate) fn new(
        root: Vec3,
        tip: Vec3,
        v_root: Vec3,
        v_tip: Vec3,
        still: f32,
        zero_length: f32,
    ) -> Option<Ribbon> {
        let b = tip - root;
        let len = b.length();
        if !(len > zero_length && len.is_finite()) {
            return None;
        }
        let axis = b / len;
        let dir = |v: Vec3| {
            if v.length() > still {
                v.try_normalize()
            } else {
                None
            }
        };
        let (r, t) = match (dir(v_root), dir(v_tip)) {
            (Some(r), Some(t)) => (r, t),
            (Some(r), None) => (r, r),
            (None, Some(t)) => (t, t),
            (None, None) => (Vec3::ZERO, Vec3::ZERO),
        };
        let cos = r.dot(t).clamp(-1.0, 1.0);
        let omega = cos.acos();
        let (interp, p, q) = if r == Vec3::ZERO {
            (Interp::Still, Vec3::ZERO, Vec3::ZERO)
        } else if omega < DEFAULT_LERP_ANGLE {
            (Interp::Lerp, r, t)
        } else {
            // Orthonormal partner of r towards t; for (nearly) opposite directions any
            // perpendicular works: take the one across the bone so the ribbon stays defined.
            let e = (t - cos * r)
                .try_normalize()
                .filter(|_| omega < std::f32::consts::PI - 1e-3);
            let e = e
                .or_else(|| axis.cross(r).try_normalize())
                .unwrap_or_else(|| r.any_orthonormal_vector());
            (Interp::Slerp, r, e)
        };
        let (n0, coll0) = end_normal(p, axis);
        let (n1, coll1) = match interp {
            Interp::Slerp => {
                let (s, c) = sin_cos_0_pi(omega);
                end_normal(c * p + s * q, axis)
            }
            _ => end_normal(q, axis),
        };
        Some(Ribbon {
            n0,
            coll0,
            n1,
            coll1,
            root,
            axis,
            inv_len: 1.0 / len,
            p,
            q,
            pb: p.dot(axis),
            qb: q.dot(axis),
            pp: p.dot(p),
            pq: p.dot(q),
            qq: q.dot(q),
            omega,
            interp,
        })
    }

    /// SMEAR Eqs. 3–6 at point `x`.
    ///
    /// # Performance
    /// About 40 flops, a polynomial `sin_cos` for slerped bones, one square root and two
    /// divisions. Hot loops call [`eval_batch`] instead.
    #[inline]
    pub(crate) fn eval(&self, x: Vec3) -> RibbonSample {
        match self.interp {
            Interp::Slerp => self.eval_slerp(x),
            Interp::Lerp => self.eval_lerp(x),
            Interp::Still => self.eval_still(x),
        }
    }

    /// SMEAR Eq. 3: offset from the root, its projection on the axis, and the unclamped ratio.
    #[inline(always)]
    fn project(&self, x: Vec3) -> (Vec3, f32, f32) {
        let d = x - self.root;
        let db = d.dot(self.axis);
        (d, db, db * self.inv_len)
    }

    /// The sample of a point beyond an end of the bone (u clamped to 0 or 1), if it is.
    #[inline(always)]
    fn beyond_ends(&self, d: Vec3, t: f32) -> Option<RibbonSample> {
        if t <= 0.0 {
            Some(RibbonSample {
                u: 0.0,
                raw: d.dot(self.n0),
                coll: self.coll0,
            })
        } else if t >= 1.0 {
            Some(RibbonSample {
                u: 1.0,
                raw: d.dot(self.n1),
                coll: self.coll1,
            })
        } else {
            None
        }
    }

    /// [`Ribbon::eval`] for an [`Interp::Slerp`] ribbon (|v(u)| = 1).
    #[inline(always)]
    pub(crate) fn eval_slerp(&self, x: Vec3) -> RibbonSample {
        let (d, db, t) = self.project(x);
        if let Some(s) = self.beyond_ends(d, t) {
            return s;
        }
        let u = smoothstep(t);
        let (s, c) = sin_cos_0_pi(u * self.omega);
        self.finish(d, db, u, c, s, 1.0)
    }

    /// [`Ribbon::eval`] for an [`Interp::Lerp`] ribbon.
    #[inline(always)]
    pub(crate) fn eval_lerp(&self, x: Vec3) -> RibbonSample {
        let (d, db, t) = self.project(x);
        if let Some(s) = self.beyond_ends(d, t) {
            return s;
        }
        let u = smoothstep(t);
        let (a, b) = (1.0 - u, u);
        let vv = a * a * self.pp + 2.0 * a * b * self.pq + b * b * self.qq;
        self.finish(d, db, u, a, b, vv)
    }

    /// [`Ribbon::eval`] for an [`Interp::Still`] ribbon: 0.
    #[inline(always)]
    pub(crate) fn eval_still(&self, x: Vec3) -> RibbonSample {
        RibbonSample {
            u: smoothstep(self.project(x).2),
            raw: 0.0,
            coll: 0.0,
        }
    }

    /// The loops of [`eval_batch`] for v(u) = a·P + b·Q, `dir(u) = (a, b, |v|²)`: first
    /// every point as beyond the bone's ends (SMEAR Eq. 6's dot product with the end normals;
    /// most of the neighbours of a bone), in one loop over whole columns; then each block of
    /// [`BATCH_LANES`] points holding a point within the span (spatially coherent in vertex
    /// order, so few blocks) runs [`Ribbon::beyond_ends`] and [`Ribbon::finish`] written as
    /// selects. Both give the bits of [`Ribbon::eval`].
    #[inline(always)]
    fn batch(
        &self,
        xs: &[f32],
        ys: &[f32],
        zs: &[f32],
        raw: &mut [f32],
        us: &mut [f32],
        colls: &mut [f32],
        dir: impl Fn(f32) -> (f32, f32, f32),
    ) {
        let n = xs.len();
        let (ys, zs) = (&ys[..n], &zs[..n]);
        let (raw, us, colls) = (&mut raw[..n], &mut us[..n], &mut colls[..n]);
        // Pass 1, every point as if beyond an end (most of a bone's neighbours are): one
        // branch-free loop the compiler vectorizes over whole columns. `u` is 0 or 1 there and
        // ½ marks a point within the bone's span for pass 2.
        let (o, a, n0, n1) = (self.root, self.axis, self.n0, self.n1);
        let (inv_len, coll0, coll1) = (self.inv_len, self.coll0, self.coll1);
        for i in 0..n {
            // `project` and `lane_ends` spelled per coordinate (same operations and order,
            // so the same bits as `Vec3::dot`).
            let (dx, dy, dz) = (xs[i] - o.x, ys[i] - o.y, zs[i] - o.z);
            let t = (dx * a.x + dy * a.y + dz * a.z) * inv_len;
            let r0 = dx * n0.x + dy * n0.y + dz * n0.z;
            let r1 = dx * n1.x + dy * n1.y + dz * n1.z;
            let (lo, hi) = (t <= 0.0, t >= 1.0);
            raw[i] = if lo { r0 } else { r1 };
            us[i] = if lo {
                0.0
            } else if hi {
                1.0
            } else {
                0.5
            };
            colls[i] = if lo { coll0 } else { coll1 };
        }
        // Pass 2: blocks holding a point within the span run `lane` (selects, vectorized).
        const L: usize = BATCH_LANES;
        let blocks = n / L * L;
        for s in (0..blocks).step_by(L) {
            let u = lanes_mut(us, s);
            let mut inside = 0u32;
            for &u in u.iter() {
                inside |= u32::from(u == 0.5);
            }
            if inside == 0 {
                continue;
            }
            let col = |c: &[f32]| -> [f32; L] { c[s..s + L].try_into().expect("L points") };
            let (x, y, z) = (col(xs), col(ys), col(zs));
            let (r, c) = (lanes_mut(raw, s), lanes_mut(colls, s));
            for l in 0..L {
                let (d, db, t) = self.project(Vec3::new(x[l], y[l], z[l]));
                (r[l], u[l], c[l]) = self.lane(d, db, t, &dir);
            }
        }
        for i in blocks..n {
            if us[i] == 0.5 {
                let (d, db, t) = self.project(Vec3::new(xs[i], ys[i], zs[i]));
                (raw[i], us[i], colls[i]) = self.lane(d, db, t, &dir);
            }
        }
    }

    /// `(raw, u, coll)` of [`Ribbon::eval`] from [`Ribbon::project`]'s `(d, db, t)`, with
    /// selects instead of branches.
    #[inline(always)]
    fn lane(
        &self,
        d: Vec3,
        db: f32,
        t: f32,
        dir: &impl Fn(f32) -> (f32, f32, f32),
    ) -> (f32, f32, f32) {
        let u = smoothstep(t);
        let (a, b, vv) = dir(u);
        let vb = a * self.pb + b * self.qb;
        let nn = vv - vb * vb;
        let ok = nn > 1e-12 * vv;
        let dn = a * d.dot(self.p) + b * d.dot(self.q) - vb * db;
        let mid_raw = if ok { dn / nn.sqrt() } else { 0.0 };
        let mid_coll = if ok { nn / vv } else { 0.0 };
        if t <= 0.0 || t >= 1.0 {
            self.lane_ends(d, t)
        } else {
            (mid_raw, u, mid_coll)
        }
    }

    /// [`Ribbon::lane`] for a point beyond an end of the bone (`t <= 0` or `t >= 1`).
    #[inline(always)]
    fn lane_ends(&self, d: Vec3, t: f32) -> (f32, f32, f32) {
        let (r0, r1) = (d.dot(self.n0), d.dot(self.n1));
        if t <= 0.0 {
            (r0, 0.0, self.coll0)
        } else {
            (r1, 1.0, self.coll1)
        }
    }

    /// SMEAR Eqs. 5–6 from v(u) = a·P + b·Q with |v|² = `vv`.
    #[inline(always)]
    fn finish(&self, d: Vec3, db: f32, u: f32, a: f32, b: f32, vv: f32) -> RibbonSample {
        let vb = a * self.pb + b * self.qb;
        let nn = vv - vb * vb;
        if nn > 1e-12 * vv {
            let dn = a * d.dot(self.p) + b * d.dot(self.q) - vb * db;
            RibbonSample {
                u,
                raw: dn / nn.sqrt(),
                coll: nn / vv,
            }
        } else {
            // Motion along the bone axis (or NaN): no ribbon normal, and w_coll = 0.
            RibbonSample {
                u,
                raw: 0.0,
                coll: 0.0,
            }
        }
    }
}

/// [`Ribbon::eval`] of `rib` at many points, bit for bit: point i is `(xs[i], ys[i], zs[i])`,
/// its sample goes to `raw[i]`, `u[i]`, `coll[i]` (only the first `xs.len()` entries of the
/// outputs are written).
///
/// # Panics
/// If an input or output column is shorter than `xs`.
///
/// # Performance
/// Branch-free columns the compiler vectorizes; the beyond-the-ends cases are selected, not
/// branched to. Compiled for baseline x86-64 and for AVX2 and picked at run time: with AVX2
/// the columns run 8 points per instruction instead of 4, with the same bits (Rust never fuses
/// or reorders float operations, so only the register width differs).
#[multiversion::multiversion(targets("x86_64+avx2"))]
pub(crate) fn eval_batch(
    rib: &Ribbon,
    xs: &[f32],
    ys: &[f32],
    zs: &[f32],
    raw: &mut [f32],
    u: &mut [f32],
    coll: &mut [f32],
) {
    let n = xs.len();
    let (ys, zs) = (&ys[..n], &zs[..n]);
    let (raw, u, coll) = (&mut raw[..n], &mut u[..n], &mut coll[..n]);
    match rib.interp {
        Interp::Slerp => rib.batch(xs, ys, zs, raw, u, coll, |u| {
            let (s, c) = sin_cos_0_pi(u * rib.omega);
            (c, s, 1.0)
        }),
        Interp::Lerp => rib.batch(xs, ys, zs, raw, u, coll, |u| {
            let (a, b) = (1.0 - u, u);
            (a, b, a * a * rib.pp + 2.0 * a * b * rib.pq + b * b * rib.qq)
        }),
        Interp::Still => {
            for i in 0..n {
                let x = Vec3::new(xs[i], ys[i], zs[i]);
                u[i] = smoothstep(rib.project(x).2);
            }
            raw.fill(0.0);
            coll.fill(0.0);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Direct transcription of SMEAR Eqs. 3–6 (slerp with sines, explicit projection) as an oracle.
    fn reference(root: Vec3, tip: Vec3, vr: Vec3, vt: Vec3, x: Vec3) -> (f32, f32, f32) {
        let b = tip - root;
        let bh = b.normalize();
        let u = smoothstep((x - root).dot(bh) / b.length());
        let (r, t) = (vr.normalize(), vt.normalize());
        let w = r.dot(t).clamp(-1.0, 1.0).acos();
        let v = if w < 0.1 {
            ((1.0 - u) * r + u * t).normalize()
        } else {
            ((1.0 - u) * w).sin() / w.sin() * r + (u * w).sin() / w.sin() * t
        };
        let n = (v - v.dot(bh) * bh).normalize();
        ((x - root).dot(n), 1.0 - v.dot(bh).powi(2), u)
    }

    #[test]
    fn matches_the_printed_equations() {
        let cases = [
            (Vec3::new(0.0, 0.0, 1.0), Vec3::new(1.0, 0.0, 0.0)),
            (Vec3::new(0.0, 1.0, 0.3), Vec3::new(0.2, 1.0, -0.1)),
            (Vec3::new(1.0, 0.2, 0.0), Vec3::new(-0.3, 1.0, 0.5)),
        ];
        let (root, tip) = (Vec3::new(0.1, -0.2, 0.3), Vec3::new(0.3, 1.5, 0.2));
        for (vr, vt) in cases {
            let rib = Ribbon::new(root, tip, vr, vt, 1e-9, 1e-9).unwrap();
            for k in 0..7 {
                let x = Vec3::new(
                    0.4 * k as f32 - 1.0,
                    0.3 * k as f32 - 0.2,
                    0.5 - 0.1 * k as f32,
                );
                let s = rib.eval(x);
                let (raw, coll, u) = reference(root, tip, vr, vt, x);
                assert!((s.raw - raw).abs() < 1e-4, "raw {} vs {raw}", s.raw);
                assert!((s.coll - coll).abs() < 1e-4, "coll {} vs {coll}", s.coll);
                assert!((s.u - u).abs() < 1e-6);
            }
        }
    }

    #[test]
    fn fast_sin_cos_is_accurate_on_0_pi() {
        let mut worst = 0.0f32;
        for i in 0..=10_000 {
            let x = std::f32::consts::PI * i as f32 / 10_000.0;
            let (s, c) = sin_cos_0_pi(x);
            worst = worst.max((s - x.sin()).abs()).max((c - x.cos()).abs());
        }
        assert!(worst < 2e-7, "max error {worst}");
    }

    /// The vectorized batch (blocks beyond the ends, mixed blocks, scalar tail) gives the
    /// bits of the scalar evaluation for slerped, lerped, still and axis-parallel motions.
    #[test]
    fn batch_equals_scalar_bit_for_bit() {
        let (root, tip) = (Vec3::new(0.1, -0.2, 0.3), Vec3::new(0.3, 1.5, 0.2));
        let motions = [
            (Vec3::new(0.0, 0.0, 1.0), Vec3::new(1.0, 0.0, 0.0)),
            (Vec3::new(1.0, 0.2, 0.0), Vec3::new(1.0, 0.21, 0.01)),
            (Vec3::ZERO, Vec3::ZERO),
            (Vec3::Y, Vec3::Y),
            (Vec3::X, -Vec3::X),
        ];
        // 61 points: 7 blocks of 8 plus a tail; a run below the root, one through the bone,
        // one beyond the tip, one interleaved, plus a NaN.
        let mut pts: Vec<Vec3> = (0..60)
            .map(|i| {
                let y = match i / 16 {
                    0 => -1.0 - 0.01 * i as f32,
                    1 => 0.1 * (i - 16) as f32,
                    2 => 2.0 + 0.01 * i as f32,
                    _ => [-0.5, 0.7, 1.8][i % 3],
                };
                Vec3::new(0.3 * (i as f32).sin(), y, 0.2 * (i as f32).cos())
            })
            .collect();
        pts.push(Vec3::NAN);
        let col = |f: fn(Vec3) -> f32| pts.iter().map(|p| f(*p)).collect::<Vec<f32>>();
        let (xs, ys, zs) = (col(|p| p.x), col(|p| p.y), col(|p| p.z));
        for (vr, vt) in motions {
            let rib = Ribbon::new(root, tip, vr, vt, 1e-9, 1e-9).unwrap();
            let n = pts.len();
            let (mut raw, mut u, mut coll) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
            eval_batch(&rib, &xs, &ys, &zs, &mut raw, &mut u, &mut coll);
            for (i, p) in pts.iter().enumerate() {
                let s = rib.eval(*p);
                let same =
                    |a: f32, b: f32| a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan());
                assert!(
                    same(s.raw, raw[i]) && same(s.u, u[i]) && same(s.coll, coll[i]),
                    "{:?} point {i}: scalar {s:?}, batch ({}, {}, {})",
                    rib.interp,
                    raw[i],
                    u[i],
                    coll[i]
                );
            }
        }
    }

    #[test]
    fn degenerate_bones_and_motions() {
        let r = Vec3::ZERO;
        assert!(Ribbon::new(r, r, Vec3::X, Vec3::X, 1e-9, 1e-6).is_none());
        // Both still: zero contribution, finite.
        let s = Ribbon::new(r, Vec3::Y, Vec3::ZERO, Vec3::ZERO, 1e-9, 1e-6)
            .unwrap()
            .eval(Vec3::X);
        assert_eq!((s.raw, s.coll), (0.0, 0.0));
        // One still joint takes the other's direction: pure X motion, offset = x.
        let s = Ribbon::new(r, Vec3::Y, Vec3::ZERO, Vec3::X, 1e-9, 1e-6)
            .unwrap()
            .eval(Vec3::new(0.5, 0.5, 0.0));
        assert!((s.raw - 0.5).abs() < 1e-6 && (s.coll - 1.0).abs() < 1e-6);
        // Motion along the bone: no normal, zero collinear weight.
        let s = Ribbon::new(r, Vec3::Y, Vec3::Y, Vec3::Y, 1e-9, 1e-6)
            .unwrap()
            .eval(Vec3::X);
        assert_eq!((s.raw, s.coll), (0.0, 0.0));
        // Opposite joint directions stay finite.
        let s = Ribbon::new(r, Vec3::Y, Vec3::X, -Vec3::X, 1e-9, 1e-6)
            .unwrap()
            .eval(Vec3::new(0.3, 0.5, 0.2));
        assert!(s.raw.is_finite() && s.coll.is_finite());
    }
}
