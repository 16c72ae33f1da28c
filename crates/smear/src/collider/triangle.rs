//! The point of a triangle nearest to a point, and which feature (vertex, edge, face) it lies
//! on — the feature selects the angle-weighted pseudo-normal of the inside test
//! (see [`super::Shape::inside`]).

use glam::Vec3;

/// Where on a triangle `[a, b, c]` the nearest point lies.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Feature {
    /// Corner `k` (0 = a, 1 = b, 2 = c).
    Vertex(usize),
    /// Edge from corner `k` to corner `(k + 1) % 3`.
    Edge(usize),
    /// The interior.
    Face,
}

/// The point of triangle `[a, b, c]` nearest to `p` and its feature (Voronoi regions of the
/// triangle, as in Ericson, *Real-Time Collision Detection*, §5.1.5).
pub(super) fn closest_point(p: Vec3, [a, b, c]: [Vec3; 3]) -> (Vec3, Feature) {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, Feature::Vertex(0));
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return (b, Feature::Vertex(1));
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return (a + ab * v, Feature::Edge(0));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return (c, Feature::Vertex(2));
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return (a + ac * w, Feature::Edge(2));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (b + (c - b) * w, Feature::Edge(1));
    }
    let denom = va + vb + vc;
    if denom.abs() <= f32::MIN_POSITIVE {
        // Degenerate (zero-area) triangle: its nearest corner.
        let k = [a, b, c]
            .iter()
            .enumerate()
            .min_by(|x, y| {
                p.distance_squared(*x.1)
                    .total_cmp(&p.distance_squared(*y.1))
            })
            .map_or(0, |(k, _)| k);
        return ([a, b, c][k], Feature::Vertex(k));
    }
    let (v, w) = (vb / denom, vc / denom);
    (a + ab * v + ac * w, Feature::Face)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_every_feature() {
        let t = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let (q, f) = closest_point(Vec3::new(0.2, 0.2, 3.0), t);
        assert_eq!(f, Feature::Face);
        assert!(q.distance(Vec3::new(0.2, 0.2, 0.0)) < 1e-6, "{q}");
        assert_eq!(
            closest_point(Vec3::new(-1.0, -1.0, 0.5), t).1,
            Feature::Vertex(0)
        );
        assert_eq!(
            closest_point(Vec3::new(2.0, -0.1, 0.0), t).1,
            Feature::Vertex(1)
        );
        assert_eq!(
            closest_point(Vec3::new(-0.1, 2.0, 0.0), t).1,
            Feature::Vertex(2)
        );
        let (q, f) = closest_point(Vec3::new(0.5, -1.0, 0.0), t);
        assert_eq!((q, f), (Vec3::new(0.5, 0.0, 0.0), Feature::Edge(0)));
        assert_eq!(
            closest_point(Vec3::new(1.0, 1.0, 0.0), t).1,
            Feature::Edge(1)
        );
        assert_eq!(
            closest_point(Vec3::new(-1.0, 0.5, 0.0), t).1,
            Feature::Edge(2)
        );
    }
}
