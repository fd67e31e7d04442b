//! Render-graph tests that need no GPU: culling, validation, ordering, merging, aliasing,
//! barriers, and a plan snapshot.

use ash::vk;
use lucent::backend::access::Access;
use lucent::graph::{CompileOptions, ImageInfo, LoadOp, PassKind, PingPong, RenderGraph};

fn info(w: u32, h: u32, format: vk::Format) -> ImageInfo {
    ImageInfo {
        width: w,
        height: h,
        format,
    }
}
const RGBA8: vk::Format = vk::Format::R8G8B8A8_UNORM;
const RGBA16F: vk::Format = vk::Format::R16G16B16A16_SFLOAT;
const CLEAR: LoadOp = LoadOp::Clear([0.0; 4]);

/// Compiles `g`, which must fail with an error containing every one of `wanted`.
fn plan_fails_naming(g: RenderGraph, wanted: &[&str]) {
    let err = g.plan(CompileOptions::default()).unwrap_err().to_string();
    for w in wanted {
        assert!(err.contains(w), "'{w}' not in: {err}");
    }
}

/// G-buffer -> lighting (same pixel) -> tonemap (sampled), like the `smoke` scene.
fn deferred_graph(with_debug_pass: bool) -> RenderGraph {
    let mut g = RenderGraph::new();
    let mut albedo = g.create_image("albedo", info(64, 64, RGBA8));
    let mut normal = g.create_image("normal", info(64, 64, RGBA16F));
    let mut depth = g.create_image("depth", info(64, 64, vk::Format::D32_SFLOAT));
    let mut hdr = g.create_image("hdr", info(64, 64, RGBA16F));
    let mut ldr = g.create_image("ldr", info(64, 64, RGBA8));
    let mut p = g.add_pass("gbuffer", PassKind::Raster);
    p.color(&mut albedo, CLEAR)
        .color(&mut normal, CLEAR)
        .depth(&mut depth, LoadOp::Clear([1.0; 4]));
    p.finish();
    let mut p = g.add_pass("lighting", PassKind::Raster);
    p.input(&albedo)
        .input(&normal)
        .input(&depth)
        .color(&mut hdr, CLEAR);
    p.finish();
    if with_debug_pass {
        let mut debug = g.create_image("debug", info(64, 64, RGBA8));
        let mut p = g.add_pass("debug-view", PassKind::Raster);
        p.sample(&normal).color(&mut debug, LoadOp::DontCare);
        p.finish();
    }
    let mut p = g.add_pass("tonemap", PassKind::Raster);
    p.sample(&hdr).color(&mut ldr, LoadOp::DontCare);
    p.finish();
    g.export_image(&ldr, Access::TransferRead);
    g
}

#[test]
fn passes_reaching_no_export_are_culled_with_their_memory() {
    let plan = deferred_graph(true)
        .plan(CompileOptions::default())
        .unwrap();
    assert_eq!(plan.culled, vec!["debug-view".to_string()]);
    let names: Vec<&str> = plan.passes.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names, ["gbuffer", "lighting", "tonemap"]);
    let debug = plan.resource_by_name("debug").unwrap();
    assert!(plan.resources[debug].lifetime.is_none());
    assert!(plan.slots.iter().all(|s| !s.resources.contains(&debug)));
    assert!(plan
        .dump()
        .contains("debug 64x64 R8G8B8A8_UNORM 0.02 MiB unused (no memory)"));
}

#[test]
fn everything_is_culled_when_nothing_is_exported() {
    let mut g = RenderGraph::new();
    let mut a = g.create_image("a", info(8, 8, RGBA8));
    let mut p = g.add_pass("draw", PassKind::Raster);
    p.color(&mut a, CLEAR);
    p.finish();
    let plan = g.plan(CompileOptions::default()).unwrap();
    assert!(plan.passes.is_empty() && plan.physical.is_empty());
}

#[test]
fn reading_what_nothing_wrote_is_an_error_naming_the_pass() {
    let mut g = RenderGraph::new();
    let never = g.create_image("never-written", info(8, 8, RGBA8));
    let mut out = g.create_image("out", info(8, 8, RGBA8));
    let mut p = g.add_pass("blur", PassKind::Raster);
    p.sample(&never).color(&mut out, CLEAR);
    p.finish();
    g.export_image(&out, Access::TransferRead);
    plan_fails_naming(g, &["'blur'", "'never-written'"]);
}

#[test]
fn loading_a_never_written_attachment_is_an_error() {
    let mut g = RenderGraph::new();
    let mut out = g.create_image("accum", info(8, 8, RGBA8));
    let mut p = g.add_pass("add-light", PassKind::Raster);
    p.color(&mut out, LoadOp::Load);
    p.finish();
    g.export_image(&out, Access::TransferRead);
    plan_fails_naming(g, &["'add-light'", "'accum'"]);
}

#[test]
fn sampling_and_writing_one_image_is_a_feedback_loop_error() {
    let mut g = RenderGraph::new();
    let mut a = g.create_image("a", info(8, 8, RGBA8));
    let mut p = g.add_pass("init", PassKind::Raster);
    p.color(&mut a, CLEAR);
    p.finish();
    let mut p = g.add_pass("self-blur", PassKind::Raster);
    let snapshot_id = a.id();
    p.sample(&a).color(&mut a, LoadOp::DontCare);
    p.finish();
    let _ = snapshot_id;
    g.export_image(&a, Access::TransferRead);
    plan_fails_naming(g, &["feedback loop"]);
}

#[test]
fn order_is_stable_declaration_order() {
    let mut g = RenderGraph::new();
    let mut outs = Vec::new();
    for i in 0..4 {
        let mut img = g.create_image(&format!("img{i}"), info(8, 8, RGBA8));
        let mut p = g.add_pass(&format!("pass{i}"), PassKind::Raster);
        p.color(&mut img, CLEAR);
        p.finish();
        outs.push(img);
    }
    for img in &outs {
        g.export_image(img, Access::TransferRead);
    }
    let plan = g.plan(CompileOptions::default()).unwrap();
    let names: Vec<&str> = plan.passes.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names, ["pass0", "pass1", "pass2", "pass3"]);
    // Independent passes never merge: nothing is read at the same pixel.
    assert_eq!(plan.physical.len(), 4);
}

#[test]
fn same_pixel_reads_merge_into_subpasses_and_sampled_reads_do_not() {
    let plan = deferred_graph(false)
        .plan(CompileOptions::default())
        .unwrap();
    let names: Vec<&str> = plan.physical.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names, ["gbuffer + lighting", "tonemap"]);
    let rp = plan.physical[0].render_pass.as_ref().unwrap();
    assert_eq!(rp.subpasses.len(), 2);
    assert_eq!(rp.subpasses[1].inputs.len(), 3);
    // One dependency 0 -> 1, by region, colour + depth writes made visible to input reads.
    assert_eq!(rp.dependencies.len(), 1);
    let dep = &rp.dependencies[0];
    assert!(dep.by_region);
    assert!(dep
        .src_access
        .contains(vk::AccessFlags2::COLOR_ATTACHMENT_WRITE));
    assert!(dep
        .src_access
        .contains(vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE));
    assert!(dep
        .dst_access
        .contains(vk::AccessFlags2::INPUT_ATTACHMENT_READ));
    // The G-buffer never leaves the render pass: its contents are not stored.
    for a in &rp.attachments {
        let name = &plan.resources[a.resource].name;
        let expect = if name == "hdr" {
            vk::AttachmentStoreOp::STORE
        } else {
            vk::AttachmentStoreOp::DONT_CARE
        };
        assert_eq!(a.store, expect, "{name}");
    }
}

#[test]
fn merging_can_be_switched_off() {
    let plan = deferred_graph(false)
        .plan(CompileOptions {
            merge: false,
            alias: true,
            ..CompileOptions::default()
        })
        .unwrap();
    let names: Vec<&str> = plan.physical.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names, ["gbuffer", "lighting", "tonemap"]);
    // Unmerged, the G-buffer must be stored and made visible to the next render pass.
    let to_lighting = &plan.physical[1].barriers;
    assert!(to_lighting
        .iter()
        .any(|b| plan.resources[b.resource].name == "albedo"
            && b.src_access
                == vk::AccessFlags2::COLOR_ATTACHMENT_WRITE
                    | vk::AccessFlags2::COLOR_ATTACHMENT_READ
            && b.new_layout == vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL));
}

#[test]
fn different_sizes_do_not_merge() {
    let mut g = RenderGraph::new();
    let mut a = g.create_image("full", info(64, 64, RGBA8));
    let mut b = g.create_image("half", info(32, 32, RGBA8));
    let mut p = g.add_pass("a", PassKind::Raster);
    p.color(&mut a, CLEAR);
    p.finish();
    let mut p = g.add_pass("b", PassKind::Raster);
    p.input(&a).color(&mut b, CLEAR);
    p.finish();
    g.export_image(&b, Access::TransferRead);
    // An input attachment must match the framebuffer: that is a pass-shape error.
    plan_fails_naming(g, &["'b'"]);
}

/// Source -> H -> V -> H -> V, alternating between two images: the blur chain of SSS.
fn ping_pong_graph() -> RenderGraph {
    let mut g = RenderGraph::new();
    let mut lit = g.create_image("lit", info(64, 64, RGBA16F));
    let mut p = g.add_pass("light", PassKind::Raster);
    p.color(&mut lit, CLEAR);
    p.finish();
    let tmp = g.create_image("tmp", info(64, 64, RGBA16F));
    let mut pair = PingPong::new(lit, tmp);
    for (i, dir) in ["h1", "v1", "h2", "v2"].iter().enumerate() {
        let _ = i;
        let (src, dst) = pair.step();
        let mut p = g.add_pass(dir, PassKind::Raster);
        p.sample(src).color(dst, LoadOp::DontCare);
        p.finish();
    }
    g.export_image(&pair.current, Access::TransferRead);
    g
}

#[test]
fn ping_pong_chain_barriers() {
    let plan = ping_pong_graph().plan(CompileOptions::default()).unwrap();
    let names: Vec<&str> = plan.physical.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(
        names,
        ["light", "h1", "v1", "h2", "v2"],
        "blurs never merge"
    );
    let lit = plan.resource_by_name("lit").unwrap();
    let tmp = plan.resource_by_name("tmp").unwrap();
    for (i, phys) in plan.physical.iter().enumerate().skip(1) {
        // Each blur reads what the previous pass wrote and overwrites what the one before read.
        let (src, dst) = if i % 2 == 1 { (lit, tmp) } else { (tmp, lit) };
        let read = phys
            .barriers
            .iter()
            .find(|b| b.resource == src)
            .expect("read barrier");
        assert_eq!(
            read.src_stage,
            vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT
        );
        assert!(read
            .src_access
            .contains(vk::AccessFlags2::COLOR_ATTACHMENT_WRITE));
        assert_eq!(read.dst_stage, vk::PipelineStageFlags2::FRAGMENT_SHADER);
        assert_eq!(read.dst_access, vk::AccessFlags2::SHADER_SAMPLED_READ);
        assert_eq!(read.old_layout, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL);
        assert_eq!(read.new_layout, vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL);
        let write = phys
            .barriers
            .iter()
            .find(|b| b.resource == dst)
            .expect("write barrier");
        assert_eq!(
            write.old_layout,
            vk::ImageLayout::UNDEFINED,
            "contents discarded"
        );
        assert_eq!(write.new_layout, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL);
        if i >= 2 {
            // Write-after-read: wait for the previous blur's sampling; no memory to flush.
            assert_eq!(write.src_stage, vk::PipelineStageFlags2::FRAGMENT_SHADER);
            assert_eq!(write.src_access, vk::AccessFlags2::NONE);
        }
        assert_eq!(phys.barriers.len(), 2);
    }
    let export = &plan.export_barriers;
    assert_eq!(export.len(), 1);
    assert_eq!(export[0].resource, lit);
    assert_eq!(export[0].new_layout, vk::ImageLayout::TRANSFER_SRC_OPTIMAL);
}

#[test]
fn aliasing_never_overlaps_lifetimes() {
    // A long chain: a0 -> a1 -> ... -> a7, each read only by the next: lifetimes of length 2.
    let mut g = RenderGraph::new();
    let mut prev = g.create_image("a0", info(64, 64, RGBA16F));
    let mut p = g.add_pass("p0", PassKind::Raster);
    p.color(&mut prev, CLEAR);
    p.finish();
    for i in 1..8 {
        let mut next = g.create_image(&format!("a{i}"), info(64, 64, RGBA16F));
        let mut p = g.add_pass(&format!("p{i}"), PassKind::Raster);
        p.sample(&prev).color(&mut next, CLEAR);
        p.finish();
        prev = next;
    }
    g.export_image(&prev, Access::TransferRead);
    let plan = g.plan(CompileOptions::default()).unwrap();
    assert!(!plan.slots.is_empty());
    for slot in &plan.slots {
        for (i, &a) in slot.resources.iter().enumerate() {
            for &b in &slot.resources[i + 1..] {
                let (a0, a1) = plan.resources[a].lifetime.unwrap();
                let (b0, b1) = plan.resources[b].lifetime.unwrap();
                assert!(a1 < b0 || b1 < a0, "{a} and {b} overlap in a slot");
            }
        }
    }
    let exported = plan.resource_by_name("a7").unwrap();
    assert!(
        plan.resources[exported].slot.is_none(),
        "exports never alias"
    );
    // Seven transient images, each alive for two passes, fit in two slots.
    assert_eq!(plan.slots.len(), 2);
    let (aliased, unaliased) = plan.transient_memory();
    assert!(aliased * 3 <= unaliased, "{aliased} vs {unaliased}");
    // Every image that takes over memory gets an aliasing barrier from UNDEFINED that waits for
    // the previous owner's reads.
    let takeovers: usize = plan
        .physical
        .iter()
        .flat_map(|p| &p.barriers)
        .filter(|b| b.aliasing)
        .inspect(|b| {
            assert_eq!(b.old_layout, vk::ImageLayout::UNDEFINED);
            assert!(b
                .src_stage
                .contains(vk::PipelineStageFlags2::FRAGMENT_SHADER));
        })
        .count();
    assert_eq!(takeovers, 7 - 2);

    let no_alias = {
        let mut g = RenderGraph::new();
        let mut a = g.create_image("x", info(8, 8, RGBA8));
        let mut p = g.add_pass("p", PassKind::Raster);
        p.color(&mut a, CLEAR);
        p.finish();
        g.export_image(&a, Access::TransferRead);
        g.plan(CompileOptions {
            merge: true,
            alias: false,
            ..CompileOptions::default()
        })
        .unwrap()
    };
    assert!(no_alias.slots.is_empty());
}

#[test]
fn plan_snapshot() {
    let plan = deferred_graph(true)
        .plan(CompileOptions::default())
        .unwrap();
    let expected = include_str!("../data/plan_deferred.txt");
    let actual = plan.dump();
    if actual != expected {
        let path =
            std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("plan_deferred.actual.txt");
        std::fs::write(&path, &actual).unwrap();
        panic!(
            "plan dump changed; actual written to {} (copy it over tests/data/plan_deferred.txt if intended)\n{actual}",
            path.display()
        );
    }
}

#[test]
fn a_depth_image_can_be_depth_tested_and_read_as_input_in_one_subpass() {
    // E.g. a lighting subpass that stencil- or depth-tests against the G-buffer's depth while
    // reconstructing positions from it: both roles, one read-only layout.
    let mut g = RenderGraph::new();
    let mut depth = g.create_image("depth", info(64, 64, vk::Format::D32_SFLOAT_S8_UINT));
    let mut hdr = g.create_image("hdr", info(64, 64, RGBA16F));
    let mut p = g.add_pass("gbuffer", PassKind::Raster);
    p.depth(&mut depth, LoadOp::Clear([1.0; 4]));
    p.finish();
    let mut p = g.add_pass("lighting", PassKind::Raster);
    p.input(&depth).depth_read(&depth).color(&mut hdr, CLEAR);
    p.finish();
    g.export_image(&hdr, Access::TransferRead);
    g.export_image(&depth, Access::TransferRead);
    let plan = g.plan(CompileOptions::default()).unwrap();
    let rp = plan.physical[0].render_pass.as_ref().unwrap();
    let lighting = &rp.subpasses[1];
    let (depth_attachment, depth_layout) = lighting.depth.unwrap();
    assert_eq!(lighting.inputs, vec![(depth_attachment, depth_layout)]);
    assert_eq!(
        depth_layout,
        vk::ImageLayout::DEPTH_STENCIL_READ_ONLY_OPTIMAL
    );
    // Its aspect covers depth and stencil, and the export waits for the store op's write.
    assert_eq!(
        plan.resources[rp.attachments[depth_attachment].resource]
            .info
            .aspect(),
        vk::ImageAspectFlags::DEPTH | vk::ImageAspectFlags::STENCIL
    );
    let export = plan
        .export_barriers
        .iter()
        .find(|b| plan.resources[b.resource].name == "depth")
        .unwrap();
    assert!(export
        .src_access
        .contains(vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE));
}
