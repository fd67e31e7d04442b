//! `lucent gallery`: every showcase scene under the techniques its materials ask for and beside
//! plain lighting, as PNGs and a Markdown page with the [`super::look`] numbers of each.
//!
//! For each scene of [`GALLERY_SCENES`] it writes `NAME.png` (the frame), `NAME-none.png`
//! (`--technique none`), `NAME-difference.png` (|frame - none| x 4) and a row of `index.md`:
//! pixels changed, technique pixels, halo pixels, and the wall time of one frame of each.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::look::{self, Look, CHANGED_THRESHOLD, HALO_THRESHOLD};
use crate::backend::shader::{PipelineCache, ShaderCompiler};
use crate::backend::GpuContext;
use crate::bake::scene::load_scene_baked;
use crate::frame::FrameSettings;
use crate::images::output::write_png_rgba8;
use crate::{LucentError, Result};

/// The scenes of the gallery: (scene, what it shows).
pub const GALLERY_SCENES: &[(&str, &str)] = &[
    (
        "showcase-translucency",
        "GDC 2011 thickness-based translucency: an ear, leaves and a wax panel lit from behind",
    ),
    (
        "showcase-skin",
        "separable SSS with d'Eon's skin profile (10x): the red terminator; the ears also translucent",
    ),
    (
        "showcase-marble",
        "separable SSS with the marble profile (5x) on veined, normal-mapped marble under a grazing light",
    ),
    (
        "showcase-layered",
        "Li et al.'s single + dipole multiple scattering in jade and wax",
    ),
    ("mixed", "every technique in one frame"),
];

/// One scene of the gallery, written.
#[derive(Clone, Debug)]
pub struct GalleryEntry {
    /// Scene name.
    pub scene: String,
    /// What it shows.
    pub shows: String,
    /// The frame's PNG.
    pub frame: PathBuf,
    /// The plain frame's PNG.
    pub plain: PathBuf,
    /// The difference PNG.
    pub difference: PathBuf,
    /// The numbers.
    pub look: Look,
}

/// Renders the gallery's `scenes` (names from [`GALLERY_SCENES`] or any scene) into `out`
/// with `settings` (size, knobs; the technique is each scene's own unless `settings` names
/// one), writes `index.md`, and returns the entries. `progress` is told each scene's name.
pub fn gallery(
    gpu: &GpuContext,
    shaders: &ShaderCompiler,
    pipeline_cache: &PipelineCache,
    scenes: &[&str],
    settings: FrameSettings,
    out: &Path,
    mut progress: impl FnMut(&str),
) -> Result<Vec<GalleryEntry>> {
    std::fs::create_dir_all(out)
        .map_err(|e| LucentError::file(out, format!("cannot create the gallery folder: {e}")))?;
    // Nothing the gallery writes may be a file a scene reads (a scene file, its mesh or a
    // texture in the same folder), checked before any work.
    let inputs: Vec<(String, PathBuf)> = scenes
        .iter()
        .flat_map(|name| crate::scene::inputs::scene_inputs(name))
        .collect();
    let outputs: Vec<PathBuf> = scenes
        .iter()
        .flat_map(|name| {
            ["", "-none", "-difference"]
                .map(|suffix| out.join(format!("{}{suffix}.png", file_stem(name))))
        })
        .chain([out.join("index.md")])
        .collect();
    crate::files::check_outputs(
        &inputs
            .iter()
            .map(|(what, path)| (what.as_str(), path.as_path()))
            .collect::<Vec<_>>(),
        &outputs
            .iter()
            .map(|p| ("--out", p.as_path()))
            .collect::<Vec<_>>(),
    )?;
    let mut entries = Vec::new();
    for &name in scenes {
        progress(name);
        let scene = load_scene_baked(name)?;
        let images = look::look(gpu, shaders, pipeline_cache, &scene, settings)?;
        let file = |suffix: &str| out.join(format!("{}{suffix}.png", file_stem(name)));
        let (w, h) = (settings.width, settings.height);
        let entry = GalleryEntry {
            scene: name.to_string(),
            shows: GALLERY_SCENES
                .iter()
                .find(|(n, _)| *n == name)
                .map_or_else(|| scene.name.clone(), |(_, s)| s.to_string()),
            frame: file(""),
            plain: file("-none"),
            difference: file("-difference"),
            look: images.look,
        };
        write_png_rgba8(&entry.frame, w, h, &images.with)?;
        write_png_rgba8(&entry.plain, w, h, &images.without)?;
        write_png_rgba8(
            &entry.difference,
            w,
            h,
            &look::difference_image(&images.with, &images.without, 4),
        )?;
        entries.push(entry);
    }
    let page = markdown(&entries, &settings, &gpu.info.describe());
    let index = out.join("index.md");
    std::fs::write(&index, page)
        .map_err(|e| LucentError::file(&index, format!("cannot write: {e}")))?;
    Ok(entries)
}

/// A file name for a scene name or path: its stem, with anything but letters, digits, `-` and
/// `_` replaced.
fn file_stem(name: &str) -> String {
    let stem = Path::new(name)
        .file_stem()
        .map_or_else(|| name.to_string(), |s| s.to_string_lossy().into_owned());
    stem.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// The gallery page: a table of the numbers, then each scene with its three pictures.
pub fn markdown(entries: &[GalleryEntry], settings: &FrameSettings, device: &str) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "# lucent gallery\n");
    let _ = writeln!(
        out,
        "{}x{}, technique `{}`, anti-aliasing `{}`, on {device}. Each scene beside plain \
         lighting (`--technique none`) and their difference (x4). *Changed*: pixels that \
         moved by more than {CHANGED_THRESHOLD}/255; *halo*: pixels of objects with no \
         technique that moved by more than {HALO_THRESHOLD}/255. Frame times are one frame \
         each (a hint; `lucent bench` measures).\n",
        settings.width,
        settings.height,
        settings.technique.name(),
        settings.antialias.name(),
    );
    let _ = writeln!(
        out,
        "| scene | changed | technique pixels | halo pixels | frame / none (ms) |\n|---|---:|---:|---:|---:|"
    );
    for e in entries {
        let _ = writeln!(
            out,
            "| `{}` | {:.1}% | {} | {} (max {}/255) | {:.0} / {:.0} |",
            e.scene,
            100.0 * e.look.changed,
            e.look.technique_pixels,
            e.look.halo_pixels,
            e.look.halo_max,
            e.look.frame_ms.0,
            e.look.frame_ms.1
        );
    }
    for e in entries {
        let name = |p: &Path| {
            p.file_name()
                .map_or_else(String::new, |n| n.to_string_lossy().into_owned())
        };
        let _ = writeln!(out, "\n## `{}`\n\n{}\n", e.scene, e.shows);
        let _ = writeln!(
            out,
            "| {} | plain lighting | difference x4 |\n|---|---|---|\n| ![]({}) | ![]({}) | ![]({}) |",
            e.scene,
            name(&e.frame),
            name(&e.plain),
            name(&e.difference)
        );
    }
    out
}
