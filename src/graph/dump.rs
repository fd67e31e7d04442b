//! The plan as text: physical passes, merged groups, barriers, lifetimes and memory.
//! Stable output (no addresses, no hash-map order), so tests can snapshot it.

use std::fmt::Write;

use ash::vk;

use super::compile::{Barrier, Plan};

fn mib(bytes: u64) -> String {
    format!("{:.2} MiB", bytes as f64 / (1024.0 * 1024.0))
}

fn layout_name(layout: vk::ImageLayout) -> String {
    match layout {
        vk::ImageLayout::UNDEFINED => "UNDEFINED".into(),
        vk::ImageLayout::GENERAL => "GENERAL".into(),
        vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL => "COLOR_ATTACHMENT".into(),
        vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL => "DEPTH_ATTACHMENT".into(),
        vk::ImageLayout::DEPTH_STENCIL_READ_ONLY_OPTIMAL => "DEPTH_READ_ONLY".into(),
        vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL => "SHADER_READ_ONLY".into(),
        vk::ImageLayout::TRANSFER_SRC_OPTIMAL => "TRANSFER_SRC".into(),
        vk::ImageLayout::TRANSFER_DST_OPTIMAL => "TRANSFER_DST".into(),
        vk::ImageLayout::PRESENT_SRC_KHR => "PRESENT_SRC".into(),
        other => format!("{other:?}"),
    }
}

/// Flags as text; empty masks print as NONE rather than nothing.
fn flags(value: impl std::fmt::Debug) -> String {
    let text = format!("{value:?}");
    if text.is_empty() {
        "NONE".into()
    } else {
        text
    }
}

fn barrier_line(plan: &Plan, b: &Barrier) -> String {
    format!(
        "{}: {} -> {} | {}/{} -> {}/{}{}",
        plan.resources[b.resource].name,
        layout_name(b.old_layout),
        layout_name(b.new_layout),
        flags(b.src_stage),
        flags(b.src_access),
        flags(b.dst_stage),
        flags(b.dst_access),
        if b.aliasing { " (aliasing)" } else { "" }
    )
}

impl Plan {
    /// Renders the plan as human-readable text.
    pub fn dump(&self) -> String {
        let mut out = String::new();
        let (aliased, unaliased) = self.transient_memory();
        let _ = writeln!(
            out,
            "plan: {} passes ({} culled), {} physical passes; merging {}, aliasing {}",
            self.passes.len(),
            self.culled.len(),
            self.physical.len(),
            if self.options.merge { "on" } else { "off" },
            if self.options.alias { "on" } else { "off" },
        );
        if !self.culled.is_empty() {
            let _ = writeln!(
                out,
                "culled (no export reached): {}",
                self.culled.join(", ")
            );
        }
        for (i, phys) in self.physical.iter().enumerate() {
            let _ = writeln!(
                out,
                "\n[{i}] \"{}\" {:?}{}",
                phys.name,
                phys.kind,
                if phys.extent.0 > 0 {
                    format!(" {}x{}", phys.extent.0, phys.extent.1)
                } else {
                    String::new()
                }
            );
            if phys.passes.len() > 1 {
                let _ = writeln!(out, "  merged: {} subpasses", phys.passes.len());
            }
            for b in &phys.barriers {
                let _ = writeln!(out, "  barrier {}", barrier_line(self, b));
            }
            if let Some(rp) = &phys.render_pass {
                for a in &rp.attachments {
                    let _ = writeln!(
                        out,
                        "  attachment {} {:?} load {:?} store {:?} {} -> {}",
                        self.resources[a.resource].name,
                        a.format,
                        a.load,
                        a.store,
                        layout_name(a.initial_layout),
                        layout_name(a.final_layout)
                    );
                }
                for (s, (&p, sub)) in phys.passes.iter().zip(&rp.subpasses).enumerate() {
                    let names = |v: &[(usize, vk::ImageLayout)]| {
                        v.iter()
                            .map(|&(a, _)| self.resources[rp.attachments[a].resource].name.clone())
                            .collect::<Vec<_>>()
                            .join(", ")
                    };
                    let _ = writeln!(
                        out,
                        "  subpass {s} {}: colors [{}] inputs [{}] depth [{}]",
                        self.passes[p].name,
                        names(&sub.colors),
                        names(&sub.inputs),
                        sub.depth
                            .map(|(a, _)| self.resources[rp.attachments[a].resource].name.clone())
                            .unwrap_or_default()
                    );
                }
                for d in &rp.dependencies {
                    let _ = writeln!(
                        out,
                        "  dependency {} -> {}: {}/{} -> {}/{}{}",
                        d.src,
                        d.dst,
                        flags(d.src_stage),
                        flags(d.src_access),
                        flags(d.dst_stage),
                        flags(d.dst_access),
                        if d.by_region { " by-region" } else { "" }
                    );
                }
            }
            for &p in &phys.passes {
                let pass = &self.passes[p];
                let uses = |v: &[super::declare::Use]| {
                    v.iter()
                        .map(|u| {
                            format!(
                                "{}@v{}({})",
                                self.resources[u.resource].name,
                                u.version,
                                u.access.short_name()
                            )
                        })
                        .collect::<Vec<_>>()
                        .join(", ")
                };
                let _ = writeln!(
                    out,
                    "  pass {}: reads [{}] writes [{}]",
                    pass.name,
                    uses(&pass.reads),
                    uses(&pass.writes)
                );
            }
        }
        if !self.export_barriers.is_empty() {
            let _ = writeln!(out, "\nend of frame (exports):");
            for b in &self.export_barriers {
                let _ = writeln!(out, "  barrier {}", barrier_line(self, b));
            }
        }
        let _ = writeln!(out, "\nresources:");
        for r in &self.resources {
            let lifetime = match r.lifetime {
                Some((a, b)) => format!("passes {a}..{b}"),
                None => "unused (no memory)".into(),
            };
            let placement = if r.imported {
                "imported".to_string()
            } else if let Some(s) = r.slot {
                format!("slot {s}")
            } else if r.lifetime.is_some() {
                if r.export.is_some() {
                    "own memory (exported)".to_string()
                } else {
                    "own memory".to_string()
                }
            } else {
                "-".to_string()
            };
            let _ = writeln!(
                out,
                "  {} {}x{} {:?} {} {} {}",
                r.name,
                r.info.width,
                r.info.height,
                r.info.format,
                mib(r.estimated_bytes()),
                lifetime,
                placement
            );
        }
        let _ = writeln!(out, "\nmemory:");
        for (i, s) in self.slots.iter().enumerate() {
            let names: Vec<&str> = s
                .resources
                .iter()
                .map(|&r| self.resources[r].name.as_str())
                .collect();
            let _ = writeln!(
                out,
                "  slot {i}: {} holds [{}]",
                mib(s.estimated_bytes),
                names.join(", ")
            );
        }
        let _ = writeln!(
            out,
            "  transient total: {} ({} without aliasing)",
            mib(aliased),
            mib(unaliased)
        );
        out
    }
}
