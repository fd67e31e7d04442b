//! [`EffectTimer`]: GPU timestamps of an effect's passes, only when the host asks for them.
//!
//! An effect recorded with `record` writes no timestamp and needs no query pool; recorded with
//! `record_timed` it writes one begin/end pair per pass into the host's command buffer (the
//! pool is reset in that command buffer first, outside any render pass) and the host reads
//! the times once that frame's fence has signalled ([`EffectTimer::results`] never waits).
//! One timer per effect and frame slot: a slot's timer is rewritten when the slot records
//! again.

use super::uploads::LeakGuard;
use super::Lucent;
use crate::backend::timer::GpuTimer;
use crate::Result;

pub use crate::backend::timer::ScopeTime as PassTime;

/// A query pool for the timestamps of one effect's passes in one frame (see the module docs).
pub struct EffectTimer {
    timer: Option<GpuTimer>,
    guard: Option<LeakGuard>,
}

impl EffectTimer {
    /// A timer for effects of up to `max_passes` passes. The queue family must have
    /// timestamps (`timestampValidBits` > 0): otherwise a [`crate::LucentError::MissingFeature`].
    pub fn new(lucent: &Lucent, max_passes: u32) -> Result<Self> {
        Ok(Self {
            timer: Some(GpuTimer::new(lucent.gpu(), max_passes)?),
            guard: Some(LeakGuard::new("EffectTimer")),
        })
    }

    /// The passes' times of the frame last recorded with this timer, or `None` while the GPU
    /// has not written them (call once that frame's fence has signalled). Never waits.
    pub fn results(&self, lucent: &Lucent) -> Result<Option<Vec<PassTime>>> {
        self.timer().results(lucent.gpu())
    }

    pub(crate) fn timer(&self) -> &GpuTimer {
        self.timer.as_ref().expect("alive until destroy")
    }

    pub(crate) fn timer_mut(&mut self) -> &mut GpuTimer {
        self.timer.as_mut().expect("alive until destroy")
    }

    /// Destroys the query pool; no frame recorded with it may still be pending.
    pub fn destroy(mut self, lucent: &Lucent) {
        if let Some(timer) = self.timer.take() {
            timer.destroy(lucent.gpu());
        }
        if let Some(guard) = self.guard.take() {
            guard.disarm();
        }
    }
}

impl std::fmt::Debug for EffectTimer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("EffectTimer").finish_non_exhaustive()
    }
}

// Timers move with their effects.
const _: () = {
    const fn send<T: Send>() {}
    send::<EffectTimer>();
};
