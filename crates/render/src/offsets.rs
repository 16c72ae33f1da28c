//! Vertex colours of motion offsets for flipbook outputs (`toonkit smear offsets -o OUT.glb`).

/// Linear-space RGBA of a motion offset δ: white at 0, red at +1, blue at −1 (linear in
/// between, clamped beyond; non-finite values are white).
pub fn offset_rgba(delta: f32) -> [f32; 4] {
    let d = if delta.is_finite() {
        delta.clamp(-1.0, 1.0)
    } else {
        0.0
    };
    if d >= 0.0 {
        [1.0, 1.0 - d, 1.0 - d, 1.0]
    } else {
        [1.0 + d, 1.0 + d, 1.0, 1.0]
    }
}

/// [`offset_rgba`] of every value (e.g. a frame-major `frames × vertices` offset buffer).
pub fn offset_colors(values: &[f32]) -> Vec<[f32; 4]> {
    values.iter().map(|&d| offset_rgba(d)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offset_colors_are_red_white_blue() {
        assert_eq!(offset_rgba(1.0), [1.0, 0.0, 0.0, 1.0]);
        assert_eq!(offset_rgba(0.0), [1.0, 1.0, 1.0, 1.0]);
        assert_eq!(offset_rgba(-1.0), [0.0, 0.0, 1.0, 1.0]);
        assert_eq!(offset_rgba(-1.4), offset_rgba(-1.0));
        assert_eq!(offset_rgba(f32::NAN), [1.0; 4]);
        let half = offset_rgba(0.5);
        assert!(half[0] == 1.0 && (half[1] - 0.5).abs() < 1e-6);
        assert_eq!(
            offset_colors(&[1.0, 0.0]),
            [offset_rgba(1.0), offset_rgba(0.0)]
        );
    }
}
