//! Where the system TrueType font is, for text drawn on the CPU: the report's plots (`report`
//! feature, drawn with plotters) and the demo's overlay (`window` feature, drawn with ab_glyph).
//! No font is compiled in: DejaVu Sans (Debian/Ubuntu: `apt-get install fonts-dejavu-core`,
//! listed in `tools/setup.sh`), or any `.ttf` named by the `LUCENT_PLOT_FONT` environment
//! variable. Finding the file needs neither crate, so it lives here, outside both features.

/// Environment variable naming a `.ttf` file to use instead of the system fonts below.
pub(crate) const FONT_ENV: &str = "LUCENT_PLOT_FONT";

/// Fonts tried in order; the first that exists and parses is used.
pub(crate) const FONT_CANDIDATES: &[&str] = &[
    // Debian/Ubuntu: fonts-dejavu-core (installed by tools/setup.sh).
    "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
    // Arch.
    "/usr/share/fonts/TTF/DejaVuSans.ttf",
    // Fedora.
    "/usr/share/fonts/dejavu-sans-fonts/DejaVuSans.ttf",
    // Alpine, older Fedora.
    "/usr/share/fonts/dejavu/DejaVuSans.ttf",
    // Debian/Ubuntu: fonts-liberation.
    "/usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf",
];

/// The font file text is drawn with outside the plots (the demo's overlay): the file named by
/// `LUCENT_PLOT_FONT` when set, else the first of the system candidates above that exists.
/// Errors say what was looked for and how to install one.
#[cfg(feature = "window")]
pub(crate) fn font_file() -> crate::Result<std::path::PathBuf> {
    use std::path::{Path, PathBuf};
    if let Some(wanted) = std::env::var_os(FONT_ENV).filter(|v| !v.is_empty()) {
        return Ok(PathBuf::from(wanted));
    }
    FONT_CANDIDATES
        .iter()
        .map(Path::new)
        .find(|p| p.is_file())
        .map(Path::to_path_buf)
        .ok_or_else(|| {
            crate::LucentError::file(
                FONT_CANDIDATES[0],
                format!(
                    "no font found (looked for {}); install one: apt-get install \
                     fonts-dejavu-core, or set {FONT_ENV} to a .ttf file",
                    FONT_CANDIDATES.join(", ")
                ),
            )
        })
}
