//! `lucent gallery`: every showcase scene under its techniques beside plain lighting and their
//! difference, as PNGs and an index.md.

use lucent::features::antialias::Antialias;
use lucent::frame::FrameSettings;
use lucent::measure::gallery::{gallery, GALLERY_SCENES};
use lucent::Result;

use crate::cli::GalleryArgs;
use crate::session::with_session;

/// Renders the gallery of `--scene` (default: every gallery scene) into `--out`.
pub fn run(args: GalleryArgs) -> Result<()> {
    let GalleryArgs {
        out,
        size,
        scene,
        aa,
        gpu,
    } = args;
    let settings = FrameSettings {
        antialias: Antialias::parse(&aa)?,
        ..FrameSettings::new(size.0, size.1)
    };
    let scenes: Vec<&str> = if scene.is_empty() {
        GALLERY_SCENES.iter().map(|(n, _)| *n).collect()
    } else {
        scene.iter().map(String::as_str).collect()
    };
    with_session(&gpu, |session| {
        let entries = gallery(
            &session.gpu,
            &session.shaders,
            &session.pipeline_cache,
            &scenes,
            settings,
            &out,
            |name| eprintln!("gallery: {name}"),
        )?;
        for e in &entries {
            println!(
                "{}: {:.1}% of pixels changed, {} halo pixels",
                e.scene,
                100.0 * e.look.changed,
                e.look.halo_pixels
            );
        }
        println!("wrote {}", out.join("index.md").display());
        Ok(())
    })
}
