//! Where the system TrueType font is, for the report's plots (`report` feature, drawn with
//! plotters). No font is compiled in: DejaVu Sans (Debian/Ubuntu: `apt-get install
//! fonts-dejavu-core`, listed in `tools/setup.sh`), or any `.ttf` named by the
//! `LUCENT_PLOT_FONT` environment variable.

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
