//! Compiling a declared graph into a plan: plain data, no GPU needed.
//!
//! The rules, in the order they run (each says why):
//! 1. Validate: every read names a version some pass wrote, or an import; otherwise the frame
//!    would read garbage, so it is an error naming the pass.
//! 2. Cull: keep only passes whose results reach an export (or that declare side effects); this is
//!    how a scene leaves out what it does not need: no pass, no memory, no shader work.
//! 3. Order: stable topological order (ties broken by declaration order) so plans are
//!    reproducible and read like the code that declared them.
//! 4. Merge: a raster pass joins the previous raster pass's render pass as a subpass when it reads
//!    what that group wrote only at the same pixel (input attachments, depth): tile-based GPUs
//!    then keep the G-buffer on chip. Never across a neighbourhood read (a blur must see its
//!    neighbours' final values, which a subpass cannot guarantee).
//! 5. Lifetimes and aliasing: transient images whose lifetimes (in physical passes) do not
//!    overlap share memory; imports and exports never alias (someone outside uses them).
//! 6. Barriers: derived from the access table, batched per physical pass; subpass dependencies
//!    inside merged groups; final transitions to each export's state.

use std::collections::{BTreeMap, HashMap};

use ash::vk;

use crate::backend::access::{Access, AccessInfo};
use crate::{LucentError, Result};

use super::declare::{LoadOp, PassKind, RenderGraph, ResourceId, Use};
use super::PassExec;

pub use super::plan::{
    AttachmentPlan, Barrier, CompileOptions, MemorySlot, PhysicalPass, Plan, PlannedPass,
    PlannedResource, RenderPassPlan, SubpassDependencyPlan, SubpassPlan,
};

/// The executors of a plan's passes, in [`Plan::passes`] order (`None` for passes declared
/// without code).
pub type PassExecs = Vec<Option<Box<dyn PassExec>>>;

/// Where a resource stands between accesses while barriers are derived.
#[derive(Clone, Copy, Debug)]
struct SyncState {
    layout: vk::ImageLayout,
    /// Last write (stage, access), if any write happened since the frame began.
    write: Option<(vk::PipelineStageFlags2, vk::AccessFlags2)>,
    /// Stages that read since the last write (a later write must wait for them).
    read_stages: vk::PipelineStageFlags2,
    /// Stage/access pairs the last write has already been made visible to.
    visible_stages: vk::PipelineStageFlags2,
    visible_access: vk::AccessFlags2,
}

impl SyncState {
    fn from_access(access: Access) -> Self {
        let info = access.info();
        SyncState {
            layout: info.layout,
            write: info.writes.then_some((info.stage, info.access)),
            read_stages: if info.writes {
                vk::PipelineStageFlags2::NONE
            } else {
                info.stage
            },
            visible_stages: vk::PipelineStageFlags2::NONE,
            visible_access: vk::AccessFlags2::NONE,
        }
    }

    /// The barrier (if any) needed before `next`, and the state after `next`.
    /// `discard` = the next access overwrites everything, so the old contents may be dropped.
    fn transition(
        &mut self,
        resource: ResourceId,
        next: AccessInfo,
        discard: bool,
        aliasing: bool,
    ) -> Option<Barrier> {
        let layout_change = self.layout != next.layout;
        let (write_stage, _) = self
            .write
            .unwrap_or((vk::PipelineStageFlags2::NONE, vk::AccessFlags2::NONE));
        let (src_stage, src_access) = self.src_scope();
        let already_visible =
            self.visible_stages.contains(next.stage) && self.visible_access.contains(next.access);
        let needs = layout_change
            || aliasing
            || (next.writes && (!write_stage.is_empty() || !self.read_stages.is_empty()))
            || (!next.writes && self.write.is_some() && !already_visible);
        let barrier = needs.then_some(Barrier {
            resource,
            src_stage,
            src_access,
            dst_stage: next.stage,
            dst_access: next.access,
            old_layout: if discard || aliasing {
                vk::ImageLayout::UNDEFINED
            } else {
                self.layout
            },
            new_layout: next.layout,
            aliasing,
        });
        if barrier.is_some() {
            self.visible_stages |= next.stage;
            self.visible_access |= next.access;
        }
        self.apply(next);
        barrier
    }

    /// What a barrier must wait for. Reads since the last write were themselves ordered after
    /// that write (a barrier or subpass dependency made it available), so waiting for the reads
    /// chains to the write and only the execution dependency is needed; with no such reads, wait
    /// for the write and make it available.
    fn src_scope(&self) -> (vk::PipelineStageFlags2, vk::AccessFlags2) {
        if !self.read_stages.is_empty() {
            (self.read_stages, vk::AccessFlags2::NONE)
        } else {
            self.write
                .unwrap_or((vk::PipelineStageFlags2::NONE, vk::AccessFlags2::NONE))
        }
    }

    /// Records `next` as having happened (no barrier: used inside render passes).
    fn apply(&mut self, next: AccessInfo) {
        self.layout = next.layout;
        if next.writes {
            self.write = Some((next.stage, next.access));
            self.read_stages = vk::PipelineStageFlags2::NONE;
            self.visible_stages = vk::PipelineStageFlags2::NONE;
            self.visible_access = vk::AccessFlags2::NONE;
        } else {
            self.read_stages |= next.stage;
        }
    }
}

impl RenderGraph {
    /// Compiles the graph into a plan plus the executors of the surviving passes (indexed like
    /// [`Plan::passes`]).
    pub fn compile(mut self, options: CompileOptions) -> Result<(Plan, PassExecs)> {
        // Split executors from the declarations so the plan stays plain data.
        let mut execs: PassExecs = self.passes.iter_mut().map(|p| p.exec.take()).collect();
        let plan = compile_plan(&self, options)?;
        let ordered = plan
            .passes
            .iter()
            .map(|p| execs[p.declared_index].take())
            .collect();
        Ok((plan, ordered))
    }

    /// Compiles only the plan (graph tests, `lucent plan`).
    pub fn plan(&self, options: CompileOptions) -> Result<Plan> {
        compile_plan(self, options)
    }
}

fn compile_plan(graph: &RenderGraph, options: CompileOptions) -> Result<Plan> {
    let res = &graph.resources;
    let decls = &graph.passes;

    // Rule 1: validate. Every image has a format of the one format table (memory estimates,
    // readback and the benchmark's copies all read it), ...
    if let Some(r) = res
        .iter()
        .find(|r| crate::backend::format::format_info(r.info.format).is_none())
    {
        return Err(LucentError::Graph(format!(
            "image '{}' has format {:?}, which lucent's format table (backend::format) does not know",
            r.name, r.info.format
        )));
    }
    // ... and every read has a writer or an import.
    let mut producer: HashMap<(ResourceId, u32), usize> = HashMap::new();
    for (index, pass) in decls.iter().enumerate() {
        for write in &pass.writes {
            producer.insert((write.resource, write.version), index);
        }
    }
    for pass in decls {
        for read in &pass.reads {
            let resource = &res[read.resource];
            if read.version == 0 && resource.import.is_none() {
                return Err(LucentError::Graph(format!(
                    "pass '{}' reads '{}', which no pass writes and which is not imported",
                    pass.name, resource.name
                )));
            }
        }
        validate_pass_shape(pass, res)?;
    }

    // Rule 2: cull. Start from the producers of every export's final version.
    let mut alive = vec![false; decls.len()];
    let mut stack: Vec<usize> = Vec::new();
    for (id, resource) in res.iter().enumerate() {
        if resource.export.is_some() {
            if resource.versions == 0 && resource.import.is_none() {
                return Err(LucentError::Graph(format!(
                    "'{}' is exported but no pass writes it",
                    resource.name
                )));
            }
            if let Some(&p) = producer.get(&(id, resource.versions)) {
                stack.push(p);
            }
        }
    }
    stack.extend(
        decls
            .iter()
            .enumerate()
            .filter(|(_, p)| p.side_effects)
            .map(|(i, _)| i),
    );
    while let Some(p) = stack.pop() {
        if std::mem::replace(&mut alive[p], true) {
            continue;
        }
        for read in &decls[p].reads {
            if let Some(&q) = producer.get(&(read.resource, read.version)) {
                stack.push(q);
            }
        }
    }
    let culled: Vec<String> = decls
        .iter()
        .zip(&alive)
        .filter(|(_, &a)| !a)
        .map(|(p, _)| p.name.clone())
        .collect();

    // Rule 3: stable topological order over RAW, WAR and WAW edges.
    let order = topological_order(decls, &alive, &producer)?;
    let passes: Vec<PlannedPass> = order
        .iter()
        .map(|&i| PlannedPass {
            name: decls[i].name.clone(),
            kind: decls[i].kind,
            declared_index: i,
            reads: decls[i].reads.clone(),
            writes: decls[i].writes.clone(),
            taps: decls[i].taps,
            mesh: decls[i].mesh.clone(),
        })
        .collect();

    // Rule 4: merge into physical passes.
    let groups = group_passes(&passes, res, options.merge);

    // Rule 5: lifetimes, usage, aliasing.
    let mut planned: Vec<PlannedResource> = res
        .iter()
        .map(|r| PlannedResource {
            name: r.name.clone(),
            info: r.info,
            imported: r.import.is_some(),
            import: r.import,
            export: r.export,
            usage: r.export.map(|a| a.info().usage).unwrap_or_default(),
            lifetime: None,
            slot: None,
        })
        .collect();
    for (g, group) in groups.iter().enumerate() {
        for &p in group {
            for u in passes[p].reads.iter().chain(&passes[p].writes) {
                let r = &mut planned[u.resource];
                r.usage |= u.access.info().usage;
                r.lifetime = Some(match r.lifetime {
                    None => (g, g),
                    Some((first, _)) => (first, g),
                });
            }
        }
    }
    let slots = if options.alias {
        assign_slots(&mut planned, options.chained_frames)
    } else {
        Vec::new()
    };

    // Rule 6: barriers, render passes, subpass dependencies. Frames submitted back to back
    // without the host waiting (`chained_frames`) first run the rule once to learn the state
    // the frame leaves every transient image and memory slot in: the next frame's first
    // access must wait for the previous frame's last, as it would for an earlier pass.
    let initial: Vec<SyncState> = res
        .iter()
        .map(|r| SyncState::from_access(r.import.map_or(Access::Undefined, |i| i.initial)))
        .collect();
    let mut start = (initial.clone(), vec![None; slots.len()]);
    if options.chained_frames {
        let mut state = start.clone();
        derive_sync(res, &passes, &groups, &planned, &mut state.0, &mut state.1);
        for (id, r) in res.iter().enumerate() {
            // Imports enter every frame in the state the host promises; transients in the
            // state the previous frame left them.
            if r.import.is_none() {
                start.0[id] = state.0[id];
            }
        }
        start.1 = state.1;
    }
    let (mut state, mut slot_owner) = start;
    let (physical, export_barriers) =
        derive_sync(res, &passes, &groups, &planned, &mut state, &mut slot_owner);

    Ok(Plan {
        options,
        resources: planned,
        passes,
        physical,
        export_barriers,
        slots,
        culled,
    })
}

/// Rule 6 over the whole frame from `state` (each resource's state as the frame starts) and
/// `slot_owner` (which member last used each memory slot, to detect an image taking over
/// aliased memory): the physical passes with their barriers and render passes, and the export
/// barriers. Leaves `state` and `slot_owner` as the frame ends.
fn derive_sync(
    res: &[super::declare::ResourceDecl],
    passes: &[PlannedPass],
    groups: &[Vec<usize>],
    planned: &[PlannedResource],
    state: &mut [SyncState],
    slot_owner: &mut [Option<ResourceId>],
) -> (Vec<PhysicalPass>, Vec<Barrier>) {
    let mut physical = Vec::with_capacity(groups.len());
    for (g, group) in groups.iter().enumerate() {
        let mut barriers = Vec::new();
        // First use of each resource in this group, in order.
        let mut firsts: BTreeMap<ResourceId, (Access, bool)> = BTreeMap::new();
        for &p in group {
            for u in passes[p].writes.iter().chain(&passes[p].reads) {
                let discard = matches!(u.load, Some(LoadOp::Clear(_)) | Some(LoadOp::DontCare));
                firsts.entry(u.resource).or_insert((u.access, discard));
            }
        }
        for (&r, &(access, discard)) in &firsts {
            // The image that used this memory before `r` takes it over, if any.
            let previous_owner = match planned[r].slot {
                Some(s) if slot_owner[s] != Some(r) => slot_owner[s].replace(r),
                _ => None,
            };
            let aliasing = previous_owner.is_some();
            if let Some(mut b) = state[r].transition(r, access.info(), discard, aliasing) {
                // Taking over memory: wait for the previous owner's last reads and writes.
                if let Some(prev) = previous_owner.map(|p| state[p]) {
                    let (stage, access) = prev.src_scope();
                    b.src_stage |= stage;
                    b.src_access |= access;
                }
                barriers.push(b);
            }
        }
        let first_kind = passes[group[0]].kind;
        let render_pass = (first_kind == PassKind::Raster)
            .then(|| plan_render_pass(group, passes, planned, state, g));
        let extent = render_pass
            .as_ref()
            .and_then(|rp| rp.attachments.first())
            .map(|a| {
                (
                    planned[a.resource].info.width,
                    planned[a.resource].info.height,
                )
            })
            .unwrap_or((0, 0));
        if render_pass.is_none() {
            // Outside render passes every access after the first needs its own barrier; a
            // compute or transfer pass is never merged, so its group has one pass.
            for &p in group {
                for u in passes[p].reads.iter().chain(&passes[p].writes) {
                    state[u.resource].apply(u.access.info());
                }
            }
        }
        let name = group
            .iter()
            .map(|&p| passes[p].name.as_str())
            .collect::<Vec<_>>()
            .join(" + ");
        physical.push(PhysicalPass {
            name,
            kind: first_kind,
            passes: group.clone(),
            extent,
            barriers,
            render_pass,
        });
    }
    let mut export_barriers = Vec::new();
    for (id, r) in res.iter().enumerate() {
        if let Some(export) = r.export {
            if let Some(b) = state[id].transition(id, export.info(), false, false) {
                export_barriers.push(b);
            }
        }
    }

    (physical, export_barriers)
}

/// Checks one pass's accesses fit its kind, and that it does not read and write one image.
fn validate_pass_shape(
    pass: &super::declare::PassDecl,
    res: &[super::declare::ResourceDecl],
) -> Result<()> {
    let err = |msg: String| Err(LucentError::Graph(format!("pass '{}': {msg}", pass.name)));
    let attachment_writes: Vec<&Use> = pass
        .writes
        .iter()
        .filter(|u| u.access.is_attachment())
        .collect();
    match pass.kind {
        PassKind::Raster => {
            if attachment_writes.is_empty() {
                return err("a raster pass must write at least one attachment".into());
            }
            let first = res[attachment_writes[0].resource].info;
            for u in pass.reads.iter().chain(&pass.writes) {
                let info = res[u.resource].info;
                if u.access.is_attachment()
                    && (info.width, info.height) != (first.width, first.height)
                {
                    return err(format!(
                        "attachment '{}' is {}x{}, others are {}x{}",
                        res[u.resource].name, info.width, info.height, first.width, first.height
                    ));
                }
            }
        }
        PassKind::Compute | PassKind::Transfer => {
            if let Some(u) = pass
                .reads
                .iter()
                .chain(&pass.writes)
                .find(|u| u.access.is_attachment())
            {
                return err(format!(
                    "'{}' is used as an attachment outside a raster pass",
                    res[u.resource].name
                ));
            }
        }
    }
    for w in &pass.writes {
        let conflicting = pass
            .reads
            .iter()
            .any(|r| r.resource == w.resource && r.access != w.access);
        if conflicting {
            return err(format!(
                "reads and writes '{}' in different ways (a feedback loop); use a ping-pong pair",
                res[w.resource].name
            ));
        }
    }
    Ok(())
}

fn topological_order(
    decls: &[super::declare::PassDecl],
    alive: &[bool],
    producer: &HashMap<(ResourceId, u32), usize>,
) -> Result<Vec<usize>> {
    let n = decls.len();
    let mut edges: Vec<Vec<usize>> = vec![Vec::new(); n];
    let add = |from: usize, to: usize, edges: &mut Vec<Vec<usize>>| {
        if from != to && alive[from] && alive[to] && !edges[from].contains(&to) {
            edges[from].push(to);
        }
    };
    for (p, pass) in decls.iter().enumerate() {
        for read in &pass.reads {
            // RAW: the writer of what we read runs first.
            if let Some(&w) = producer.get(&(read.resource, read.version)) {
                add(w, p, &mut edges);
            }
            // WAR: we read before the next version overwrites it.
            if let Some(&w) = producer.get(&(read.resource, read.version + 1)) {
                add(p, w, &mut edges);
            }
        }
        for write in &pass.writes {
            // WAW: versions are written in order.
            if let Some(&w) = producer.get(&(write.resource, write.version + 1)) {
                add(p, w, &mut edges);
            }
        }
    }
    let mut indegree = vec![0usize; n];
    for targets in &edges {
        for &t in targets {
            indegree[t] += 1;
        }
    }
    let mut ready: std::collections::BTreeSet<usize> =
        (0..n).filter(|&i| alive[i] && indegree[i] == 0).collect();
    let mut order = Vec::new();
    while let Some(p) = ready.pop_first() {
        order.push(p);
        for &t in &edges[p] {
            indegree[t] -= 1;
            if indegree[t] == 0 {
                ready.insert(t);
            }
        }
    }
    if order.len() != alive.iter().filter(|&&a| a).count() {
        return Err(LucentError::Graph("the passes form a cycle".into()));
    }
    Ok(order)
}

/// Rule 4. Returns groups of indices into `passes`.
fn group_passes(
    passes: &[PlannedPass],
    res: &[super::declare::ResourceDecl],
    merge: bool,
) -> Vec<Vec<usize>> {
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for (i, pass) in passes.iter().enumerate() {
        let joins = merge
            && pass.kind == PassKind::Raster
            && groups.last().is_some_and(|g| {
                passes[g[0]].kind == PassKind::Raster && can_merge(g, pass, passes, res)
            });
        if joins {
            groups.last_mut().expect("checked above").push(i);
        } else {
            groups.push(vec![i]);
        }
    }
    groups
}

/// A raster pass joins a group when it reads something the group wrote, reads all of it only at
/// the same pixel, and draws at the same size.
fn can_merge(
    group: &[usize],
    pass: &PlannedPass,
    passes: &[PlannedPass],
    res: &[super::declare::ResourceDecl],
) -> bool {
    let written: Vec<ResourceId> = group
        .iter()
        .flat_map(|&g| passes[g].writes.iter().map(|u| u.resource))
        .collect();
    let group_extent = passes[group[0]]
        .writes
        .iter()
        .find(|u| u.access.is_attachment())
        .map(|u| (res[u.resource].info.width, res[u.resource].info.height));
    let pass_extent = pass
        .writes
        .iter()
        .find(|u| u.access.is_attachment())
        .map(|u| (res[u.resource].info.width, res[u.resource].info.height));
    if group_extent != pass_extent {
        return false;
    }
    let mut same_pixel_dependency = false;
    for read in &pass.reads {
        if written.contains(&read.resource) {
            if !read.access.is_attachment() {
                return false; // neighbourhood read of something the group wrote
            }
            same_pixel_dependency = true;
        }
    }
    same_pixel_dependency
}

/// Builds the render pass of a raster group, advancing `state` through it.
fn plan_render_pass(
    group: &[usize],
    passes: &[PlannedPass],
    planned: &[PlannedResource],
    state: &mut [SyncState],
    group_index: usize,
) -> RenderPassPlan {
    let mut rp = RenderPassPlan::default();
    let mut index_of: HashMap<ResourceId, usize> = HashMap::new();
    // Per attachment: last (subpass, access) to derive dependencies.
    let mut last_use: HashMap<ResourceId, (usize, Access)> = HashMap::new();
    let mut deps: BTreeMap<(usize, usize), SubpassDependencyPlan> = BTreeMap::new();
    for (s, &p) in group.iter().enumerate() {
        let mut sub = SubpassPlan::default();
        let uses: Vec<&Use> = passes[p].writes.iter().chain(&passes[p].reads).collect();
        for u in &uses {
            let info = u.access.info();
            // A Load write also appears as a read of the same access; count it once.
            if !u.access.is_attachment() {
                // Sampled reads inside a raster pass: synchronised by the barrier before it.
                if let Some(&(prev, prev_access)) = last_use.get(&u.resource) {
                    add_dependency(&mut deps, prev, s, prev_access, u.access, false);
                }
                continue;
            }
            let a = *index_of.entry(u.resource).or_insert_with(|| {
                let r = &planned[u.resource];
                let (load, clear) = match u.load {
                    Some(LoadOp::Clear(c)) => (vk::AttachmentLoadOp::CLEAR, c),
                    Some(LoadOp::DontCare) => (vk::AttachmentLoadOp::DONT_CARE, [0.0; 4]),
                    _ => (vk::AttachmentLoadOp::LOAD, [0.0; 4]),
                };
                rp.attachments.push(AttachmentPlan {
                    resource: u.resource,
                    format: r.info.format,
                    load,
                    clear,
                    // Kept only if someone reads it after this render pass.
                    store: if r.export.is_some()
                        || r.imported
                        || r.lifetime.is_some_and(|(_, last)| last > group_index)
                    {
                        vk::AttachmentStoreOp::STORE
                    } else {
                        vk::AttachmentStoreOp::DONT_CARE
                    },
                    initial_layout: info.layout,
                    final_layout: info.layout,
                });
                rp.attachments.len() - 1
            });
            rp.attachments[a].final_layout = info.layout;
            // Each role once per attachment. A depth image may hold two roles in one subpass:
            // read-only depth-stencil attachment (tests) and depth input attachment, both in the
            // read-only layout.
            match u.access {
                Access::ColorAttachmentWrite => {
                    if sub.colors.iter().any(|&(x, _)| x == a) {
                        continue;
                    }
                    sub.colors.push((a, info.layout));
                }
                Access::DepthAttachmentWrite | Access::DepthAttachmentRead => {
                    if sub.depth.is_some_and(|(x, _)| x == a) {
                        continue;
                    }
                    sub.depth = Some((a, info.layout));
                }
                _ => {
                    if sub.inputs.iter().any(|&(x, _)| x == a)
                        || sub.colors.iter().any(|&(x, _)| x == a)
                    {
                        continue;
                    }
                    sub.inputs.push((a, info.layout));
                }
            }
            if let Some(&(prev, prev_access)) = last_use.get(&u.resource) {
                if prev != s {
                    add_dependency(&mut deps, prev, s, prev_access, u.access, true);
                }
            }
        }
        for u in &uses {
            last_use.insert(u.resource, (s, u.access));
            state[u.resource].apply(u.access.info());
        }
        rp.subpasses.push(sub);
    }
    // An attachment's last access is its store operation, STORE and DONT_CARE alike (both are
    // writes in the attachment stage at the end of the render pass), even when its last use
    // inside was an input-attachment read: later barriers (an export, or an image taking over
    // its aliased memory) must wait for and make available that write.
    for attachment in &rp.attachments {
        let info = if planned[attachment.resource].info.aspect() == vk::ImageAspectFlags::COLOR {
            Access::ColorAttachmentWrite.info()
        } else {
            Access::DepthAttachmentWrite.info()
        };
        let s = &mut state[attachment.resource];
        s.write = Some((info.stage, info.access));
        s.read_stages = vk::PipelineStageFlags2::NONE;
        s.visible_stages = vk::PipelineStageFlags2::NONE;
        s.visible_access = vk::AccessFlags2::NONE;
    }
    rp.dependencies = deps.into_values().collect();
    rp
}

fn add_dependency(
    deps: &mut BTreeMap<(usize, usize), SubpassDependencyPlan>,
    src: usize,
    dst: usize,
    src_access: Access,
    dst_access: Access,
    by_region: bool,
) {
    let (s, d) = (src_access.info(), dst_access.info());
    if !s.writes && !d.writes {
        return; // read after read needs no ordering
    }
    let dep = deps.entry((src, dst)).or_insert(SubpassDependencyPlan {
        src: src as u32,
        dst: dst as u32,
        src_stage: vk::PipelineStageFlags2::NONE,
        src_access: vk::AccessFlags2::NONE,
        dst_stage: vk::PipelineStageFlags2::NONE,
        dst_access: vk::AccessFlags2::NONE,
        by_region: true,
    });
    dep.src_stage |= s.stage;
    if s.writes {
        dep.src_access |= s.access;
    }
    dep.dst_stage |= d.stage;
    dep.dst_access |= d.access;
    dep.by_region &= by_region;
}

/// Greedy interval colouring: each transient image goes into the slot that freed up last before
/// it starts (best fit by size); imported and exported images never share memory.
fn assign_slots(planned: &mut [PlannedResource], chained_frames: bool) -> Vec<MemorySlot> {
    let mut candidates: Vec<ResourceId> = (0..planned.len())
        .filter(|&r| {
            planned[r].lifetime.is_some() && !planned[r].imported && planned[r].export.is_none()
        })
        .collect();
    candidates.sort_by_key(|&r| (planned[r].lifetime.map(|l| l.0), r));
    let mut slots: Vec<MemorySlot> = Vec::new();
    let mut slot_end: Vec<usize> = Vec::new();
    // A barrier on an image covers that image's memory only: an image larger than the slot's
    // last owner would inherit, beyond the last owner's extent, writes of an earlier owner that
    // no barrier made available (a write-after-write hazard). So an image takes over a slot only
    // if it is no larger than the last owner, or no earlier owner reached past the last one
    // (the memory beyond is untouched this frame). Chained frames (frames in flight) touched
    // the whole slot in the previous frame: there, never larger.
    let mut slot_last_bytes: Vec<u64> = Vec::new();
    let mut slot_earlier_bytes: Vec<u64> = Vec::new();
    for r in candidates {
        let (first, last) = planned[r].lifetime.expect("filtered above");
        let bytes = planned[r].estimated_bytes();
        let fits = |s: usize| {
            bytes <= slot_last_bytes[s]
                || (!chained_frames && slot_earlier_bytes[s] <= slot_last_bytes[s])
        };
        let free = (0..slots.len())
            .filter(|&s| slot_end[s] < first && fits(s))
            .min_by_key(|&s| slots[s].estimated_bytes.abs_diff(bytes));
        let s = match free {
            Some(s) => s,
            None => {
                slots.push(MemorySlot {
                    resources: Vec::new(),
                    estimated_bytes: 0,
                });
                slot_end.push(0);
                slot_last_bytes.push(u64::MAX);
                slot_earlier_bytes.push(0);
                slots.len() - 1
            }
        };
        if slot_last_bytes[s] != u64::MAX {
            slot_earlier_bytes[s] = slot_earlier_bytes[s].max(slot_last_bytes[s]);
        }
        slots[s].resources.push(r);
        slots[s].estimated_bytes = slots[s].estimated_bytes.max(bytes);
        slot_end[s] = last;
        slot_last_bytes[s] = bytes;
        planned[r].slot = Some(s);
    }
    slots
}
