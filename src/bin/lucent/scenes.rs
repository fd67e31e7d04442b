//! `lucent scenes`: the built-in scenes, one per line with what each shows.

use lucent::{scene, Result};

/// Prints every built-in scene's name and description.
pub fn run() -> Result<()> {
    for (name, description) in scene::BUILTIN_SCENES {
        println!("{name:<12} {description}");
    }
    Ok(())
}
