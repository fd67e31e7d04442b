//! `lucent gallery`: every showcase scene under the techniques its materials ask for (and
//! `showcase-skin` under 2-D Burley too) and beside plain lighting, as PNGs and a Markdown page
//! with the [`super::look`] numbers of each.
//!
//! For each entry of [`GALLERY_SCENES`] (a scene, under its materials' techniques or a named
//! one) it writes `NAME.png` (the frame; `NAME-TECHNIQUE.png` under a named technique),
//! `NAME-none.png` (`--technique none`), `NAME-difference.png` (|frame - none| x 4) and a row
//! of `index.md`: pixels changed, technique pixels, halo pixels, and the wall time of one frame
//! of each.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::look::{self, Look, CHANGED_THRESHOLD, HALO_THRESHOLD};
use crate::backend::shader::{PipelineCache, ShaderCompiler};
use crate::backend::GpuContext;
use crate::bake::scene::load_scene_baked;
use crate::frame::{FrameSettings, Technique};
use crate::images::output::write_png_rgba8;
use crate::{LucentError, Result};

/// One picture of the gallery: a scene, the technique it is shown under (`None`: what its
/// materials ask for, `--technique auto`) and what it shows.
#[derive(Clone, Copy, Debug)]
pub struct GalleryScene<'a> {
    /// Scene name (a built-in scene or a scene file).
    pub scene: &'a str,
    /// A technique's command-line name (`lucent render --technique`), or `None` for what the
    /// scene's materials ask for.
    pub technique: Option<&'a str>,
    /// What it shows (empty: the scene's own name).
    pub shows: &'a str,
}

/// The gallery's pictures, in order.
pub const GALLERY_SCENES: &[GalleryScene<'static>] = &[
    GalleryScene {
        scene: "showcase-translucency",
        technique: None,
        shows: "GDC 2011 thickness-based translucency: an ear, leaves and a wax panel lit from \
                behind",
    },
    GalleryScene {
        scene: "showcase-skin",
        technique: None,
        shows: "separable SSS on Lee Perry-Smith's scanned head: Jensen's skin1 at physical \
                scale, its colour map after the scatter; the red terminator, the ear glowing \
                against the back light (the medium's transmission through its thickness)",
    },
    GalleryScene {
        scene: "showcase-skin",
        technique: Some("burley"),
        shows: "the same head under 2-D Burley diffusion (Christensen and Burley's profile \
                importance-sampled around each pixel, `--technique burley`)",
    },
    GalleryScene {
        scene: "showcase-marble",
        technique: None,
        shows: "separable SSS with the marble profile (5x) on veined, normal-mapped marble under \
                a grazing light",
    },
    GalleryScene {
        scene: "showcase-layered",
        technique: None,
        shows: "Li et al.'s single + dipole multiple scattering in jade and wax",
    },
    GalleryScene {
        scene: "mixed",
        technique: None,
        shows: "every technique in one frame",
    },
];

impl GalleryScene<'_> {
    /// The stem of its PNGs: the scene's file stem, then `-TECHNIQUE` under a named technique.
    pub fn stem(&self) -> String {
        match self.technique {
            Some(t) => format!("{}-{}", file_stem(self.scene), file_stem(t)),
            None => file_stem(self.scene),
        }
    }

    /// How `index.md` names it: the scene, and the technique when one is named.
    pub fn title(&self) -> String {
        match self.technique {
            Some(t) => format!("`{}` under `{t}`", self.scene),
            None => format!("`{}`", self.scene),
        }
    }
}

/// One scene of the gallery, written.
#[derive(Clone, Debug)]
pub struct GalleryEntry {
    /// Scene name (and the technique, when the entry names one), as `index.md` titles it.
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
    /// The scene's credits (its assets' licences ask for them wherever they are shown).
    pub credits: Vec<String>,
}

/// Renders the gallery's `scenes` ([`GALLERY_SCENES`], or any others) into `out` with
/// `settings` (size, knobs; the technique is each entry's own when it names one, else the one
/// `settings` names), writes `index.md`, and returns the entries. `progress` is told each scene's name. A technique name no technique
/// has is an error before anything is rendered.
pub fn gallery(
    gpu: &GpuContext,
    shaders: &ShaderCompiler,
    pipeline_cache: &PipelineCache,
    scenes: &[GalleryScene<'_>],
    settings: FrameSettings,
    out: &Path,
    mut progress: impl FnMut(&str),
) -> Result<Vec<GalleryEntry>> {
    std::fs::create_dir_all(out)
        .map_err(|e| LucentError::file(out, format!("cannot create the gallery folder: {e}")))?;
    // Nothing the gallery writes may be a file a scene reads (a scene file, its mesh or a
    // texture in the same folder), checked before any work.
    let techniques = scenes
        .iter()
        .map(|s| s.technique.map(Technique::parse).transpose())
        .collect::<Result<Vec<_>>>()?;
    let inputs: Vec<(String, PathBuf)> = scenes
        .iter()
        .flat_map(|s| crate::scene::inputs::scene_inputs(s.scene))
        .collect();
    let outputs: Vec<PathBuf> = scenes
        .iter()
        .flat_map(|s| {
            ["", "-none", "-difference"].map(|suffix| out.join(format!("{}{suffix}.png", s.stem())))
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
    for (subject, technique) in scenes.iter().zip(techniques) {
        progress(subject.scene);
        let scene = load_scene_baked(subject.scene)?;
        let settings = FrameSettings {
            technique: technique.unwrap_or(settings.technique),
            ..settings
        };
        let images = look::look(gpu, shaders, pipeline_cache, &scene, settings)?;
        let file = |suffix: &str| out.join(format!("{}{suffix}.png", subject.stem()));
        let (w, h) = (settings.width, settings.height);
        let entry = GalleryEntry {
            scene: subject.title(),
            shows: if subject.shows.is_empty() {
                scene.name.clone()
            } else {
                subject.shows.to_string()
            },
            frame: file(""),
            plain: file("-none"),
            difference: file("-difference"),
            look: images.look,
            credits: scene.credits.clone(),
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
        "{}x{}, technique `{}` unless a title names another, anti-aliasing `{}`, on {device}. \
         Each scene beside plain \
         lighting (`--technique none`) and their difference (x4). *Changed*: pixels that \
         moved by more than {CHANGED_THRESHOLD}/255, of the frame and of the objects the \
         techniques render; *halo*: pixels of objects with no \
         technique that moved by more than {HALO_THRESHOLD}/255. Frame times are one frame \
         each (a hint; `lucent bench` measures).\n",
        settings.width,
        settings.height,
        settings.technique.name(),
        settings.antialias.name(),
    );
    let _ = writeln!(
        out,
        "| scene | changed | changed on objects | technique pixels | halo pixels | frame / none (ms) |\n|---|---:|---:|---:|---:|---:|"
    );
    for e in entries {
        let _ = writeln!(
            out,
            "| {} | {:.1}% | {:.1}% | {} | {} (max {}/255) | {:.0} / {:.0} |",
            e.scene,
            100.0 * e.look.changed,
            100.0 * e.look.changed_on_objects,
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
        let _ = writeln!(out, "\n## {}\n\n{}\n", e.scene, e.shows);
        let _ = writeln!(
            out,
            "| {} | plain lighting | difference x4 |\n|---|---|---|\n| ![]({}) | ![]({}) | ![]({}) |",
            e.scene,
            name(&e.frame),
            name(&e.plain),
            name(&e.difference)
        );
        for credit in &e.credits {
            let _ = writeln!(out, "\n*{credit}*");
        }
    }
    out
}
