//! The line of action as two piecewise-rigid chains hanging from a common root (Section 3.1).
//!
//! Elements are numbered in *joint order*: element `j` joins joint `j` and joint `j + 1`, joint
//! `0` being the stroke's start and joint `N` its end. The root is joint `r = N / 2`, at the
//! stroke's arc-length midpoint. The hierarchy runs outward from the root:
//!
//! * element `r` is the hierarchy's root element; its angle `γ_r` is the absolute direction
//!   (radians, counter-clockwise from +x) of the segment from joint `r` to joint `r + 1`;
//! * elements `r + 1 .. N` (forward chain) store the bend relative to their parent `j − 1`;
//! * element `r − 1` stores its outward direction (joint `r` → joint `r − 1`) relative to the
//!   *reversed* root element, so a straight line has all local angles zero except `γ_r`;
//! * elements `r − 2 .. 0` (backward chain) store the bend relative to their parent `j + 1`,
//!   measured along the outward direction.
//!
//! Every local angle therefore turns everything outboard of it counter-clockwise when it
//! grows, which is what the elastic model of Section 3.2 needs.

use std::f64::consts::PI;

use glam::DVec2;

use crate::error::LoaError;

/// Wraps an angle to `(−π, π]`.
pub(crate) fn wrap_angle(a: f64) -> f64 {
    let w = a - (2.0 * PI) * ((a + PI) / (2.0 * PI)).floor();
    if w <= -PI {
        w + 2.0 * PI
    } else {
        w
    }
}

/// Unit vector at angle `a`.
#[inline]
pub(crate) fn unit(a: f64) -> DVec2 {
    let (s, c) = a.sin_cos();
    DVec2::new(c, s)
}

/// Counter-clockwise perpendicular: the velocity of `v` rotating at unit angular speed.
#[inline]
pub(crate) fn perp(v: DVec2) -> DVec2 {
    DVec2::new(-v.y, v.x)
}

/// A line of action: a root position plus `N` local angles and `N` element lengths.
#[derive(Debug, Clone, PartialEq)]
pub struct Chain {
    root: DVec2,
    angles: Vec<f64>,
    lengths: Vec<f64>,
}

impl Chain {
    /// Builds a chain. `angles` and `lengths` must have the same even, non-zero length; all
    /// values finite and lengths non-negative.
    pub fn new(root: DVec2, angles: Vec<f64>, lengths: Vec<f64>) -> Result<Self, LoaError> {
        check_element_count(angles.len())?;
        if lengths.len() != angles.len() {
            return Err(LoaError::InvalidParameter {
                name: "lengths",
                value: lengths.len() as f64,
                expected: "one length per angle",
            });
        }
        if !root.is_finite() || angles.iter().any(|a| !a.is_finite()) {
            return Err(LoaError::InvalidParameter {
                name: "angles",
                value: f64::NAN,
                expected: "finite root and angles",
            });
        }
        if let Some(l) = lengths.iter().find(|l| !(l.is_finite() && **l >= 0.0)) {
            return Err(LoaError::InvalidParameter {
                name: "lengths",
                value: *l,
                expected: "finite lengths >= 0",
            });
        }
        Ok(Self {
            root,
            angles,
            lengths,
        })
    }

    /// Builds the chain whose joints are `joints` (`N + 1` points, `N` even), root at the
    /// middle joint. Zero-length elements get the direction of their parent.
    pub fn from_joints(joints: &[DVec2]) -> Result<Self, LoaError> {
        let n = joints.len().saturating_sub(1);
        check_element_count(n)?;
        if joints.iter().any(|p| !p.is_finite()) {
            return Err(LoaError::InvalidParameter {
                name: "joints",
                value: f64::NAN,
                expected: "finite joint positions",
            });
        }
        let r = n / 2;
        let mut lengths = vec![0.0; n];
        let mut dirs = vec![0.0; n];
        // Forward chain (outward = increasing index).
        let mut previous = 0.0;
        for j in r..n {
            let d = joints[j + 1] - joints[j];
            lengths[j] = d.length();
            let dir = if lengths[j] > 0.0 {
                d.y.atan2(d.x)
            } else {
                previous
            };
            dirs[j] = dir;
            previous = dir;
        }
        // Backward chain (outward = decreasing index); parent of r − 1 is the reversed root.
        previous = dirs[r] + PI;
        for j in (0..r).rev() {
            let d = joints[j] - joints[j + 1];
            lengths[j] = d.length();
            let dir = if lengths[j] > 0.0 {
                d.y.atan2(d.x)
            } else {
                previous
            };
            dirs[j] = dir;
            previous = dir;
        }
        let mut angles = vec![0.0; n];
        angles[r] = dirs[r];
        for j in r + 1..n {
            angles[j] = wrap_angle(dirs[j] - dirs[j - 1]);
        }
        if r > 0 {
            angles[r - 1] = wrap_angle(dirs[r - 1] - dirs[r] - PI);
            for j in (0..r - 1).rev() {
                angles[j] = wrap_angle(dirs[j] - dirs[j + 1]);
            }
        }
        Ok(Self {
            root: joints[r],
            angles,
            lengths,
        })
    }

    /// A straight chain of `elements` elements of length `length` each, centered on `root`,
    /// pointing along `direction` (radians).
    pub fn straight(
        root: DVec2,
        direction: f64,
        elements: usize,
        length: f64,
    ) -> Result<Self, LoaError> {
        check_element_count(elements)?;
        let mut angles = vec![0.0; elements];
        angles[elements / 2] = direction;
        Self::new(root, angles, vec![length; elements])
    }

    /// Number of rigid elements `N`.
    pub fn elements(&self) -> usize {
        self.angles.len()
    }

    /// Index `r = N / 2` of the root joint (and of the hierarchy's root element).
    pub fn root_index(&self) -> usize {
        self.angles.len() / 2
    }

    /// Root position `x_root`.
    pub fn root(&self) -> DVec2 {
        self.root
    }

    /// Local angles `γ_j` in joint order (see the module documentation).
    pub fn angles(&self) -> &[f64] {
        &self.angles
    }

    /// Element lengths `l_j` in joint order.
    pub fn lengths(&self) -> &[f64] {
        &self.lengths
    }

    /// Mutable access to the local angles (the representation stays valid for any finite
    /// values).
    pub fn angles_mut(&mut self) -> &mut [f64] {
        &mut self.angles
    }

    /// Sets the root position.
    pub fn set_root(&mut self, root: DVec2) {
        self.root = root;
    }

    /// Total length of the line.
    pub fn total_length(&self) -> f64 {
        self.lengths.iter().sum()
    }

    /// Absolute outward direction `θ_j` of every element (forward kinematics of the angles).
    pub fn directions(&self) -> Vec<f64> {
        let n = self.elements();
        let r = self.root_index();
        let mut dirs = vec![0.0; n];
        dirs[r] = self.angles[r];
        for j in r + 1..n {
            dirs[j] = dirs[j - 1] + self.angles[j];
        }
        if r > 0 {
            dirs[r - 1] = dirs[r] + PI + self.angles[r - 1];
            for j in (0..r - 1).rev() {
                dirs[j] = dirs[j + 1] + self.angles[j];
            }
        }
        dirs
    }

    /// Joint positions `x_loa(s_j)`, `N + 1` points from the stroke's start to its end
    /// (forward kinematics).
    pub fn joints(&self) -> Vec<DVec2> {
        let mut out = vec![DVec2::ZERO; self.elements() + 1];
        self.joints_into(&mut out);
        out
    }

    /// Forward kinematics into a caller-provided buffer of `N + 1` points.
    pub fn joints_into(&self, out: &mut [DVec2]) {
        let n = self.elements();
        let r = self.root_index();
        let dirs = self.directions();
        if out.len() < n + 1 {
            return;
        }
        out[r] = self.root;
        for j in r..n {
            out[j + 1] = out[j] + self.lengths[j] * unit(dirs[j]);
        }
        for j in (0..r).rev() {
            out[j] = out[j + 1] + self.lengths[j] * unit(dirs[j]);
        }
    }

    /// The point at normalized chain length `u ∈ [0, 1]` (0 = joint 0, 1 = joint N) and the
    /// element it lies on.
    pub fn point_at(&self, u: f64) -> (DVec2, usize) {
        let joints = self.joints();
        let total = self.total_length();
        let mut s = if u.is_finite() {
            u.clamp(0.0, 1.0)
        } else {
            0.0
        } * total;
        for j in 0..self.elements() {
            let l = self.lengths[j];
            if s <= l || j + 1 == self.elements() {
                let t = if l > 0.0 {
                    (s / l).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                return (joints[j].lerp(joints[j + 1], t), j);
            }
            s -= l;
        }
        (joints[0], 0)
    }
}

/// Hierarchy helpers shared by the fit, the dynamics and the wobble.
pub(crate) mod hierarchy {
    /// Joint an element rotates about (its inboard end).
    #[inline]
    pub(crate) fn pivot(r: usize, element: usize) -> usize {
        if element >= r {
            element
        } else {
            element + 1
        }
    }

    /// Whether rotating element `a` moves element `e` (a is `e` or one of its ancestors).
    #[inline]
    pub(crate) fn moves(r: usize, a: usize, e: usize) -> bool {
        if a == r {
            true
        } else if a > r {
            e >= a
        } else {
            e <= a
        }
    }
}

/// Checks that `n` is a valid element count (even and at least 2).
pub(crate) fn check_element_count(n: usize) -> Result<(), LoaError> {
    if n < 2 || n % 2 != 0 {
        return Err(LoaError::InvalidParameter {
            name: "elements",
            value: n as f64,
            expected: "an even number of chain elements >= 2 (the root splits the line in two)",
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn joints_round_trip_through_local_angles() {
        let joints: Vec<DVec2> = (0..=6)
            .map(|i| {
                let t = i as f64 * 0.5;
                DVec2::new(t.cos() * 3.0, t.sin() * 2.0 + 0.3 * t)
            })
            .collect();
        let chain = Chain::from_joints(&joints).unwrap();
        assert_eq!(chain.root_index(), 3);
        for (a, b) in chain.joints().iter().zip(&joints) {
            assert!((*a - *b).length() < 1e-12, "{a} vs {b}");
        }
    }

    #[test]
    fn straight_line_has_zero_bends() {
        let joints: Vec<DVec2> = (0..=4).map(|i| DVec2::new(i as f64, i as f64)).collect();
        let chain = Chain::from_joints(&joints).unwrap();
        let a = chain.angles();
        assert!((a[2] - PI / 4.0).abs() < 1e-12);
        for (j, v) in a.iter().enumerate() {
            if j != 2 {
                assert!(v.abs() < 1e-12, "element {j}: {v}");
            }
        }
    }

    #[test]
    fn odd_element_counts_are_rejected() {
        assert!(Chain::straight(DVec2::ZERO, 0.0, 3, 1.0).is_err());
        assert!(Chain::straight(DVec2::ZERO, 0.0, 0, 1.0).is_err());
    }

    #[test]
    fn wrap_angle_range() {
        for a in [-7.0, -PI, -1.0, 0.0, PI, 4.0, 100.0] {
            let w = wrap_angle(a);
            assert!(w > -PI - 1e-12 && w <= PI + 1e-12);
            assert!(
                ((a - w) / (2.0 * PI)).fract().abs() < 1e-9
                    || ((a - w) / (2.0 * PI)).fract().abs() > 1.0 - 1e-9
            );
        }
    }
}
