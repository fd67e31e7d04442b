//! Setup work a host submits itself ([`Uploads`]), and the leak detector for what a host must
//! destroy itself ([`leaked`]).
//!
//! Building a renderer uploads meshes, textures and tables. lucent never submits on the host's
//! queue nor waits on its device: the copies are recorded into a command buffer the host gives
//! ([`Uploads`]), the host submits it with whatever else it records (a loading frame, its own
//! uploads), and frees lucent's staging memory once that submission has completed
//! ([`Uploads::release`]), as it frees its own.
//!
//! Forgetting `destroy` on a renderer, or `release` on uploads, leaks GPU memory into the host's
//! allocator. Rust cannot destroy them on drop (destruction needs the [`Lucent`] and the host's
//! word that the GPU is done with them), so dropping one undestroyed is logged as an error and
//! counted ([`leaked`]), never silent.

use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};

use ash::vk;

use super::Lucent;
use crate::backend::SetupKept;
use crate::{LucentError, Result};

/// How many lucent objects were dropped without their `destroy` / `release` since the process
/// started (each also logged as an error naming it). A host's tests can assert it stays 0.
pub fn leaked() -> usize {
    LEAKS.load(Ordering::Relaxed)
}

static LEAKS: AtomicUsize = AtomicUsize::new(0);

/// Logs and counts its owner's drop unless [`LeakGuard::disarm`]ed by the owner's `destroy`.
#[derive(Debug)]
pub(crate) struct LeakGuard {
    what: String,
    armed: bool,
}

impl LeakGuard {
    pub(crate) fn new(what: impl Into<String>) -> Self {
        Self {
            what: what.into(),
            armed: true,
        }
    }

    /// The owner was destroyed properly.
    pub(crate) fn disarm(mut self) {
        self.armed = false;
    }
}

impl Drop for LeakGuard {
    fn drop(&mut self) {
        if self.armed {
            LEAKS.fetch_add(1, Ordering::Relaxed);
            log::error!(
                "lucent: {} was dropped without being destroyed: its GPU memory and objects leak \
                 (call its destroy / release once the GPU is done with it)",
                self.what
            );
        }
    }
}

/// Identifies a [`Lucent`], so uploads are released into the allocator they came from.
pub(crate) fn next_lucent_id() -> u64 {
    static NEXT: AtomicU64 = AtomicU64::new(1);
    NEXT.fetch_add(1, Ordering::Relaxed)
}

/// A host command buffer that renderers record their uploads into, and the staging memory
/// those copies read until the host's submission of it has completed.
///
/// ```text
/// let mut uploads = unsafe { lucent.uploads(cmd) };   // cmd: the host's, recording
/// let renderer = SceneRenderer::new(&lucent, &mut uploads, &scene, w, h, format)?;
/// // end cmd, submit it (before or as the start of the first frame that records `renderer`)
/// // ... once its fence has signalled:
/// unsafe { uploads.release(&lucent) }?;
/// ```
///
/// Each copy ends with a full memory barrier: every later command on the same queue (this
/// command buffer or a later submission) sees the data. A renderer recorded on another queue
/// needs the host's semaphore between the two submissions.
///
/// A build that fails (a description refused, the host's allocator out of memory) returns its
/// error and leaves the command buffer valid to submit, with the host's own work in it: the
/// images and buffers it had made and recorded copies into are destroyed only at
/// [`Uploads::release`], with the staging memory.
pub struct Uploads {
    cmd: vk::CommandBuffer,
    lucent_id: u64,
    kept: SetupKept,
    guard: Option<LeakGuard>,
}

impl std::fmt::Debug for Uploads {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Uploads")
            .field("cmd", &self.cmd)
            .field("kept", &self.kept)
            .finish()
    }
}

impl Uploads {
    /// Uploads recorded into `cmd` for renderers built from `lucent`.
    ///
    /// # Safety
    ///
    /// `cmd` is a primary command buffer of the host's device, in the recording state, outside
    /// any render pass, for a queue of the family lucent was given; it stays recording while
    /// renderers are built with these uploads, and the host submits it before any frame that
    /// records those renderers (or records them after it in the same command buffer).
    pub(crate) unsafe fn new(lucent: &Lucent, cmd: vk::CommandBuffer) -> Self {
        Self {
            cmd,
            lucent_id: lucent.id(),
            kept: SetupKept::default(),
            guard: None,
        }
    }

    /// Runs `build` with its uploads recorded into this command buffer.
    pub(crate) fn record<T>(
        &mut self,
        lucent: &Lucent,
        what: &str,
        build: impl FnOnce() -> Result<T>,
    ) -> Result<T> {
        if lucent.id() != self.lucent_id {
            return Err(LucentError::InvalidInput(format!(
                "{what}: the uploads were begun with another Lucent (staging memory would be \
                 freed into the wrong allocator)"
            )));
        }
        // SAFETY: `Uploads::new`'s contract is record_setup_into's.
        let (built, kept) = unsafe { lucent.gpu().record_setup_into(self.cmd, build) };
        if !kept.is_empty() && self.guard.is_none() {
            self.guard = Some(LeakGuard::new(format!(
                "Uploads (staging memory recorded into command buffer {:?})",
                self.cmd
            )));
        }
        self.kept.extend(kept);
        built
    }

    /// The command buffer the uploads go into.
    pub fn command_buffer(&self) -> vk::CommandBuffer {
        self.cmd
    }

    /// Whether nothing was recorded (nothing to release).
    pub fn is_empty(&self) -> bool {
        self.kept.is_empty()
    }

    /// Staging memory held until [`Uploads::release`], in bytes.
    pub fn staging_bytes(&self) -> u64 {
        self.kept.staging_bytes()
    }

    /// Frees the staging memory and destroys what failed builds left (see above). On error
    /// (another `Lucent`) nothing is freed and `self` keeps it.
    ///
    /// # Safety
    ///
    /// The submission holding the command buffer has completed (its fence signalled), or the
    /// command buffer was never submitted (reset or freed by the host).
    pub unsafe fn release(&mut self, lucent: &Lucent) -> Result<()> {
        if lucent.id() != self.lucent_id {
            return Err(LucentError::InvalidInput(
                "Uploads::release: these uploads belong to another Lucent".into(),
            ));
        }
        std::mem::take(&mut self.kept).destroy(lucent.gpu());
        if let Some(guard) = self.guard.take() {
            guard.disarm();
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_object_dropped_without_destroy_is_counted_and_a_destroyed_one_is_not() {
        let before = leaked();
        LeakGuard::new("a destroyed renderer").disarm();
        assert_eq!(leaked(), before);
        drop(LeakGuard::new("a forgotten renderer"));
        // Other tests of the process may leak too; this one added at least its own.
        assert!(leaked() > before);
    }
}
