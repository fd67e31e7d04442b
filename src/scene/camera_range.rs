//! The camera's depth range against the depth buffer: the warning scene files and glTF
//! cameras give when `far / near` is more than a 32-bit depth buffer resolves.

/// Largest `far / near` a scene may have without a warning: the 32-bit float depth buffer
/// (standard, not reversed, depth) then resolves 0.6% of the distance at the far plane.
pub const MAX_DEPTH_RATIO: f32 = 1e5;

/// The warning for a depth range the depth buffer cannot resolve, with the numbers, or `None`.
///
/// With depth `d = f/(f-n) (1 - n/z)` stored as f32 (spacing `2^-24` just below 1), two
/// surfaces at distance `z` are told apart when they are `z^2 2^-24 / n` apart, and a surface
/// beyond `n 2^25` gets the depth the buffer is cleared to (1) and fails the depth test: it
/// vanishes. `distance` is the camera's distance to its target, where the step is reported.
pub fn depth_range_warning(near: f32, far: f32, distance: f32) -> Option<String> {
    let ratio = far / near;
    if ratio <= MAX_DEPTH_RATIO {
        return None;
    }
    // f64: near 1e-7 squared and divided must not round to 0 or overflow.
    let (n, f, d) = (
        f64::from(near),
        f64::from(far),
        f64::from(distance).min(f64::from(far)),
    );
    let step = d * d * 2f64.powi(-24) / n;
    let lost = n * 2f64.powi(25);
    let vanish = if lost < f {
        format!(
            "; surfaces farther than {lost:.3} from the camera get the far plane's depth and \
             vanish"
        )
    } else {
        String::new()
    };
    // Tiny and huge numbers in exponent form (`1e-7`, not `0.0000001`).
    let num = |x: f64| {
        if x != 0.0 && !(1e-3..1e6).contains(&x.abs()) {
            format!("{x:.3e}")
        } else {
            format!("{x:.3}")
        }
    };
    Some(format!(
        "near = {near:e} and far = {far} (far/near = {ratio:.1e}) is more than the 32-bit depth \
         buffer resolves: at the target's distance ({}) its step is {}, so surfaces closer \
         together than that are not told apart{vanish}; raise `near` or lower `far` to keep \
         far/near under {MAX_DEPTH_RATIO:.0e}",
        num(d),
        num(step)
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn depth_ranges_beyond_the_depth_buffer_warn_with_the_numbers() {
        assert_eq!(depth_range_warning(0.1, 100.0, 5.0), None);
        let w = depth_range_warning(1e-7, 100.0, 5.0).unwrap();
        assert!(
            w.contains("near = 1e-7")
                && w.contains("far/near = 1.0e9")
                && w.contains("vanish")
                && w.contains("3.355")
                && w.contains("step is 14.901"),
            "{w}"
        );
        // Beyond the limit but nothing vanishes: the step is reported, not a vanishing distance.
        let w = depth_range_warning(1e-3, 200.0, 10.0).unwrap();
        assert!(w.contains("2.0e5") && !w.contains("vanish"), "{w}");
    }
}
