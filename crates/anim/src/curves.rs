//! Polylines with a width and a colour per point: motion lines as curves (what USD's
//! `BasisCurves` and a renderer's hair/curve primitives draw), beside the tube meshes that
//! glTF and OBJ need.

use glam::Vec3;

/// Linear curves of one frame: `counts[c]` consecutive points per curve, every point with
/// its width (the diameter, scene units) and RGBA colour (linear RGB and opacity).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Curves {
    /// Points of every curve, curve after curve.
    pub points: Vec<Vec3>,
    /// Number of points of each curve (each at least 2).
    pub counts: Vec<u32>,
    /// Width at each point.
    pub widths: Vec<f32>,
    /// RGBA colour at each point.
    pub colors: Vec<[f32; 4]>,
}

impl Curves {
    /// Appends one curve; fewer than 2 points append nothing.
    pub fn push(&mut self, points: impl IntoIterator<Item = (Vec3, f32, [f32; 4])>) {
        let start = self.points.len();
        for (p, w, c) in points {
            self.points.push(p);
            self.widths.push(w);
            self.colors.push(c);
        }
        let n = self.points.len() - start;
        if n < 2 {
            self.points.truncate(start);
            self.widths.truncate(start);
            self.colors.truncate(start);
        } else {
            self.counts.push(n as u32);
        }
    }

    /// Removes every curve (keeping the allocations).
    pub fn clear(&mut self) {
        self.points.clear();
        self.counts.clear();
        self.widths.clear();
        self.colors.clear();
    }

    /// Whether there is no curve.
    pub fn is_empty(&self) -> bool {
        self.counts.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_single_point_is_no_curve() {
        let mut c = Curves::default();
        c.push([(Vec3::ZERO, 1.0, [1.0; 4])]);
        assert!(c.is_empty() && c.points.is_empty());
        c.push([(Vec3::ZERO, 1.0, [1.0; 4]), (Vec3::X, 0.5, [0.0; 4])]);
        assert_eq!((c.counts.as_slice(), c.widths.len()), (&[2][..], 2));
    }
}
