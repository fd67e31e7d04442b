//! `lucent gallery`: every showcase scene under its techniques beside plain lighting and their
//! difference, as PNGs and an index.md.

use lucent::features::antialias::Antialias;
use lucent::frame::FrameSettings;
use lucent::measure::gallery::{gallery, GalleryScene, GALLERY_SCENES};
use lucent::Result;

use crate::cli::GalleryArgs;
use crate::session::with_session;

/// Renders the gallery of `--scene` (default: every gallery scene) into `--out`, each under
/// `--technique` when it is given.
pub fn run(args: GalleryArgs) -> Result<()> {
    let GalleryArgs {
        out,
        size,
        scene,
        technique,
        aa,
        gpu,
    } = args;
    let settings = FrameSettings {
        antialias: Antialias::parse(&aa)?,
        ..FrameSettings::new(size.0, size.1)
    };
    let named: Vec<&str> = if scene.is_empty() {
        // Every gallery scene once.
        let mut names: Vec<&str> = Vec::new();
        for s in GALLERY_SCENES {
            if !names.contains(&s.scene) {
                names.push(s.scene);
            }
        }
        names
    } else {
        scene.iter().map(String::as_str).collect()
    };
    let scenes: Vec<GalleryScene<'_>> = match (&technique, scene.is_empty()) {
        (None, true) => GALLERY_SCENES.to_vec(),
        _ => named
            .iter()
            .map(|&name| GalleryScene {
                scene: name,
                technique: technique.as_deref(),
                // The built-in gallery's words where they describe the same picture.
                shows: GALLERY_SCENES
                    .iter()
                    .find(|s| s.scene == name && s.technique == technique.as_deref())
                    .map_or("", |s| s.shows),
            })
            .collect(),
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
