//! FXAA in f64: the twin of `glsl/post/fxaa.frag`, run on the same 8-bit intermediate image
//! (sRGB-encoded RGB, luma in alpha) with bilinear, clamp-to-edge sampling, so a test can hold
//! the GPU's anti-aliased frame against it pixel by pixel. The shader fetches texels and
//! computes the few bilinear values FXAA needs itself (the mean of a pixel pair at an edge
//! probe, a blend of two pixels along one axis at the end): the same numbers as the bilinear
//! samples here, since every probe lies on a pixel pair (whole strides) and the final tap
//! moves along one axis only.

/// The intermediate image FXAA reads: RGBA8 rows top first, alpha the luma of the encoded RGB.
pub struct LdrImage<'a> {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width * height * 4` bytes.
    pub rgba8: &'a [u8],
}

/// The thresholds and search of the shader (see its comments).
const EDGE_THRESHOLD: f64 = 0.125;
const EDGE_THRESHOLD_MIN: f64 = 0.0625;
const SUBPIXEL: f64 = 0.75;
const STRIDES: [f64; 12] = [1.0, 1.0, 1.0, 1.0, 1.0, 2.0, 2.0, 2.0, 2.0, 2.0, 4.0, 8.0];

/// The luma the tonemap writes into alpha for sRGB-encoded `rgb` in [0, 1] (Rec. 601 weights).
pub fn luma(rgb: [f64; 3]) -> f64 {
    0.299 * rgb[0] + 0.587 * rgb[1] + 0.114 * rgb[2]
}

impl LdrImage<'_> {
    fn texel(&self, x: i64, y: i64) -> [f64; 4] {
        let x = x.clamp(0, i64::from(self.width) - 1) as usize;
        let y = y.clamp(0, i64::from(self.height) - 1) as usize;
        let i = (y * self.width as usize + x) * 4;
        std::array::from_fn(|c| f64::from(self.rgba8[i + c]) / 255.0)
    }

    /// Bilinear sample at normalised `(u, v)`, clamped to the edge, as a sampler with linear
    /// filtering samples.
    fn sample(&self, u: f64, v: f64) -> [f64; 4] {
        let x = u * f64::from(self.width) - 0.5;
        let y = v * f64::from(self.height) - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let (a, b) = (self.texel(x0, y0), self.texel(x0 + 1, y0));
        let (c, d) = (self.texel(x0, y0 + 1), self.texel(x0 + 1, y0 + 1));
        std::array::from_fn(|i| {
            let top = a[i] + (b[i] - a[i]) * fx;
            let bottom = c[i] + (d[i] - c[i]) * fx;
            top + (bottom - top) * fy
        })
    }
}

/// The anti-aliased pixel (`x`, `y`) as sRGB-encoded RGB in [0, 1], and whether it was treated
/// as an edge (a pixel below the contrast thresholds is its own texel, unchanged).
pub fn fxaa_pixel(image: &LdrImage<'_>, x: u32, y: u32) -> ([f64; 3], bool) {
    let (tx, ty) = (1.0 / f64::from(image.width), 1.0 / f64::from(image.height));
    let (u, v) = ((f64::from(x) + 0.5) * tx, (f64::from(y) + 0.5) * ty);
    let at = |dx: i64, dy: i64| image.texel(i64::from(x) + dx, i64::from(y) + dy);
    let centre = at(0, 0);
    let l_m = centre[3];
    let (l_n, l_s, l_w, l_e) = (at(0, -1)[3], at(0, 1)[3], at(-1, 0)[3], at(1, 0)[3]);
    let lo = l_m.min(l_n).min(l_s).min(l_w).min(l_e);
    let hi = l_m.max(l_n).max(l_s).max(l_w).max(l_e);
    let range = hi - lo;
    if range < EDGE_THRESHOLD_MIN.max(hi * EDGE_THRESHOLD) {
        return ([centre[0], centre[1], centre[2]], false);
    }
    let (l_nw, l_ne, l_sw, l_se) = (at(-1, -1)[3], at(1, -1)[3], at(-1, 1)[3], at(1, 1)[3]);
    let average = (2.0 * (l_n + l_s + l_w + l_e) + (l_nw + l_ne + l_sw + l_se)) / 12.0;
    let sub = ((average - l_m).abs() / range).clamp(0.0, 1.0);
    let sub = sub * sub * (3.0 - 2.0 * sub);
    let sub = sub * sub * SUBPIXEL;
    let across_rows = (l_nw - 2.0 * l_w + l_sw).abs()
        + 2.0 * (l_n - 2.0 * l_m + l_s).abs()
        + (l_ne - 2.0 * l_e + l_se).abs();
    let across_columns = (l_nw - 2.0 * l_n + l_ne).abs()
        + 2.0 * (l_w - 2.0 * l_m + l_e).abs()
        + (l_sw - 2.0 * l_s + l_se).abs();
    let horizontal = across_rows >= across_columns;
    let (l_before, l_after) = if horizontal { (l_n, l_s) } else { (l_w, l_e) };
    let (grad_before, grad_after) = ((l_before - l_m).abs(), (l_after - l_m).abs());
    let toward_before = grad_before >= grad_after;
    let mut step_across = if horizontal { ty } else { tx };
    if toward_before {
        step_across = -step_across;
    }
    let edge_mean = 0.5 * (l_m + if toward_before { l_before } else { l_after });
    let gradient_scaled = 0.25 * grad_before.max(grad_after);
    let (mut on_u, mut on_v) = (u, v);
    if horizontal {
        on_v += 0.5 * step_across;
    } else {
        on_u += 0.5 * step_across;
    }
    let along = if horizontal { (tx, 0.0) } else { (0.0, ty) };
    let luma_at = |p: (f64, f64)| image.sample(p.0, p.1)[3];
    let mut p_neg = (on_u - along.0, on_v - along.1);
    let mut p_pos = (on_u + along.0, on_v + along.1);
    let mut end_neg = luma_at(p_neg) - edge_mean;
    let mut end_pos = luma_at(p_pos) - edge_mean;
    let mut done_neg = end_neg.abs() >= gradient_scaled;
    let mut done_pos = end_pos.abs() >= gradient_scaled;
    for stride in STRIDES.iter().skip(1) {
        if done_neg && done_pos {
            break;
        }
        if !done_neg {
            p_neg = (p_neg.0 - along.0 * stride, p_neg.1 - along.1 * stride);
            end_neg = luma_at(p_neg) - edge_mean;
            done_neg = end_neg.abs() >= gradient_scaled;
        }
        if !done_pos {
            p_pos = (p_pos.0 + along.0 * stride, p_pos.1 + along.1 * stride);
            end_pos = luma_at(p_pos) - edge_mean;
            done_pos = end_pos.abs() >= gradient_scaled;
        }
    }
    let (dist_neg, dist_pos) = if horizontal {
        (u - p_neg.0, p_pos.0 - u)
    } else {
        (v - p_neg.1, p_pos.1 - v)
    };
    let nearer_neg = dist_neg < dist_pos;
    let dist = dist_neg.min(dist_pos);
    let span = (dist_neg + dist_pos).max(1e-6);
    let centre_below = l_m - edge_mean < 0.0;
    let good_end = ((if nearer_neg { end_neg } else { end_pos }) < 0.0) != centre_below;
    let offset = if good_end { 0.5 - dist / span } else { 0.0 };
    let offset = offset.max(sub);
    let (mut su, mut sv) = (u, v);
    if horizontal {
        sv += offset * step_across;
    } else {
        su += offset * step_across;
    }
    let c = image.sample(su, sv);
    ([c[0], c[1], c[2]], true)
}

/// The whole anti-aliased image as RGBA8 (alpha 255), and how many pixels were edges.
pub fn fxaa_rgba8(image: &LdrImage<'_>) -> (Vec<u8>, usize) {
    let mut out = Vec::with_capacity(image.rgba8.len());
    let mut edges = 0;
    for y in 0..image.height {
        for x in 0..image.width {
            let (c, edge) = fxaa_pixel(image, x, y);
            edges += usize::from(edge);
            out.extend(c.map(|v| (v * 255.0).round().clamp(0.0, 255.0) as u8));
            out.push(255);
        }
    }
    (out, edges)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An image of `w x h` from an encoded-RGB function, luma in alpha as the tonemap writes.
    fn image(w: u32, h: u32, f: impl Fn(u32, u32) -> [f64; 3]) -> Vec<u8> {
        let mut out = Vec::new();
        for y in 0..h {
            for x in 0..w {
                let c = f(x, y).map(|v| (v * 255.0).round() as u8);
                let l = luma(c.map(|v| f64::from(v) / 255.0));
                out.extend(c);
                out.push((l * 255.0).round() as u8);
            }
        }
        out
    }

    #[test]
    fn flat_regions_are_copied_exactly() {
        let rgba = image(16, 16, |x, _| [0.2 + 0.01 * f64::from(x), 0.5, 0.3]);
        let ldr = LdrImage {
            width: 16,
            height: 16,
            rgba8: &rgba,
        };
        let (out, edges) = fxaa_rgba8(&ldr);
        assert_eq!(edges, 0);
        for (a, b) in out.chunks(4).zip(rgba.chunks(4)) {
            assert_eq!(&a[..3], &b[..3]);
        }
    }

    #[test]
    fn a_stair_step_edge_becomes_a_ramp() {
        // A nearly horizontal black/white edge: y < 8 + x / 8 is white.
        let (w, h) = (32, 16);
        let rgba = image(w, h, |x, y| {
            if f64::from(y) < 4.0 + f64::from(x) / 8.0 {
                [1.0; 3]
            } else {
                [0.0; 3]
            }
        });
        let ldr = LdrImage {
            width: w,
            height: h,
            rgba8: &rgba,
        };
        let (out, edges) = fxaa_rgba8(&ldr);
        assert!(edges > 0);
        // Along the edge, pixels get intermediate values (a ramp), never outside [0, 1].
        let grey = out.chunks(4).filter(|p| p[0] > 20 && p[0] < 235).count();
        assert!(grey >= w as usize / 2, "only {grey} blended pixels");
    }
}
