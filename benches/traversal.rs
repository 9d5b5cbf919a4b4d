//! `cargo bench --bench traversal -- [SCENE.gltf] [--spp N] [--size N] [--integrator NAME]
//! [--max-depth N]`: Tesela's ray throughput inside the renderer against raw `obvhs` CWBVH
//! traversal **on the same rays** (issue 5's 70% target). One thread throughout, so the
//! figures do not depend on scheduling.
//!
//! 1. Renders the scene (default: the built-in `cornell-spheres`) three times and takes the
//!    renderer's rays/s of the fastest: every ray cast (camera, shadow, bounce) over the whole
//!    render time, shading and sampling included.
//! 2. Records the same render's rays (`render::record_rays`: origin, direction, `tmax`, and
//!    closest hit, any hit, or emission of a path's last segment).
//! 3. Replays them (a) the way the renderer answers them (last segments through
//!    `RenderScene::emission_along`), (b) through Tesela's `Accel` as plain closest/any-hit
//!    queries, and (c) through a CWBVH that `obvhs` builds over the same triangles with the
//!    same parameters, intersected the way obvhs' own examples do (its `RtTriangle` in BVH
//!    order, `ray_traverse` for closest hits and last segments, `ray_traverse_miss` for
//!    shadow rays).
//!
//! Prints the rates and their ratios to (c), and the share of the render spent answering rays
//! (a / whole render). Nothing is asserted: speed is measured.

use glam::Vec3A;
use obvhs::{
    BvhBuildParams,
    cwbvh::builder::build_cwbvh_from_tris,
    ray::{Ray, RayHit},
    rt_triangle::RtTriangle,
    triangle::Triangle,
};
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};
use tesela::emitter::LightChoice;
use tesela::render::{self, RenderOptions};
use tesela::render_scene::{Ctx, RayKind, RayQuery, RenderScene};
use tesela::sampler::SobolSampler;
use tesela::scene::{builtin, gltf};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // `cargo test --benches` runs bench binaries without `--bench`: stay tiny there.
    let quick = !std::env::args().any(|a| a == "--bench");
    let mut args = std::env::args().skip(1).filter(|a| a != "--bench");
    let mut path = None;
    let mut opts = RenderOptions {
        width: if quick { 16 } else { 256 },
        height: if quick { 16 } else { 256 },
        spp: if quick { 1 } else { 8 },
        max_depth: 2,
        integrator: "direct_mis".into(),
        threads: 1,
        ..Default::default()
    };
    while let Some(a) = args.next() {
        let mut value = || args.next().ok_or(format!("{a} needs a value"));
        match a.as_str() {
            "--spp" => opts.spp = value()?.parse()?,
            "--size" => {
                opts.width = value()?.parse()?;
                opts.height = opts.width;
            }
            "--integrator" => opts.integrator = value()?,
            "--max-depth" => opts.max_depth = value()?.parse()?,
            _ if a.starts_with("--") => return Err(format!("unknown option {a}").into()),
            _ => path = Some(a),
        }
    }
    let scene = match &path {
        Some(p) => gltf::load(std::path::Path::new(p))?,
        None => builtin::by_name("cornell-spheres").unwrap(),
    };
    let name = path.as_deref().unwrap_or("cornell-spheres");
    let rs = RenderScene::new(scene, LightChoice::Power);

    // 1. The renderer: the fastest of three renders, as the replays below are timed.
    let mut stats = None::<render::RenderStats>;
    for _ in 0..3 {
        let (_, s) = render::render(&rs, &opts, &AtomicBool::new(false), &|_, _, _| {})?;
        if stats.as_ref().is_none_or(|b| s.seconds < b.seconds) {
            stats = Some(s);
        }
    }
    let stats = stats.expect("three renders");
    let renderer = stats.rays as f64 / stats.seconds;

    // 2. Its rays.
    let rays = render::record_rays(&rs, &opts)?;
    let count = |k: RayKind| rays.iter().filter(|r| r.kind == k).count();

    // 3a. Tesela, the renderer's way.
    let mut ctx = Ctx::new(SobolSampler::new(0, 0, 0));
    let accel = rs.accel();
    let (own_s, own_hits) = best_of(3, || {
        let mut hits = 0usize;
        for r in &rays {
            let hit = match r.kind {
                RayKind::Closest => accel.intersect(r.o, r.d, 0.0, r.tmax).is_some(),
                RayKind::Any => accel.occluded(r.o, r.d, 0.0, r.tmax),
                RayKind::Emission => rs.emission_along(&mut ctx, r.o, r.d).is_some(),
            };
            hits += hit as usize;
        }
        hits
    });

    // 3b. Tesela's Accel, plain queries.
    let (tesela_s, tesela_hits) = best_of(3, || {
        let mut hits = 0usize;
        for r in &rays {
            let hit = match r.kind {
                RayKind::Any => accel.occluded(r.o, r.d, 0.0, r.tmax),
                _ => accel.intersect(r.o, r.d, 0.0, r.tmax).is_some(),
            };
            hits += hit as usize;
        }
        hits
    });

    // 3c. Raw obvhs on the same triangles.
    let tris: Vec<Triangle> = rs
        .scene
        .meshes
        .iter()
        .flat_map(|m| {
            m.indices.iter().map(|t| {
                let [a, b, c] = t.map(|i| Vec3A::from(m.positions[i as usize]));
                Triangle {
                    v0: a,
                    v1: b,
                    v2: c,
                }
            })
        })
        .collect();
    let bvh = build_cwbvh_from_tris(
        &tris,
        BvhBuildParams::medium_build(),
        &mut Duration::default(),
    );
    let bvh_tris: Vec<RtTriangle> = bvh
        .primitive_indices
        .iter()
        .map(|&i| (&tris[i as usize]).into())
        .collect();
    let obvhs_rays: Vec<(Ray, bool)> = rays
        .iter()
        .map(|r| (to_obvhs(r), r.kind != RayKind::Any))
        .collect();
    let (raw_s, raw_hits) = best_of(3, || {
        let mut hits = 0usize;
        let f = |ray: &Ray, id: usize| bvh_tris[id].intersect(ray);
        for (ray, closest) in &obvhs_rays {
            let hit = if *closest {
                bvh.ray_traverse(*ray, &mut RayHit::none(), f)
            } else {
                !bvh.ray_traverse_miss(*ray, f)
            };
            hits += hit as usize;
        }
        hits
    });

    let n = rays.len() as f64;
    let (own, tesela, raw) = (n / own_s, n / tesela_s, n / raw_s);
    println!(
        "scene {name}: {} triangles, {}x{} {} spp {}, max depth {}, 1 thread",
        rs.triangle_count(),
        opts.width,
        opts.height,
        opts.spp,
        opts.integrator,
        opts.max_depth
    );
    println!(
        "rays: {} ({} closest-hit, {} shadow, {} last segments); rays cast by the render: {}",
        rays.len(),
        count(RayKind::Closest),
        count(RayKind::Any),
        count(RayKind::Emission),
        stats.rays
    );
    println!(
        "hits/emission found: renderer's way {own_hits}, Accel {tesela_hits}, obvhs {raw_hits}"
    );
    let row = |what: &str, rate: f64| {
        println!(
            "{what:<44} {:>8.3} M rays/s  {:>5.2}x raw obvhs",
            rate / 1e6,
            rate / raw
        )
    };
    row("renderer (whole render, every ray cast)", renderer);
    row("the same rays answered the renderer's way", own);
    row("the same rays, plain Tesela Accel queries", tesela);
    row("the same rays, raw obvhs", raw);
    println!(
        "share of the render spent answering rays: {:.0}%",
        100.0 * own_s / stats.seconds
    );
    Ok(())
}

/// The recorded query as an obvhs ray (`-0.0` direction components made `+0.0`, as Tesela
/// does: obvhs misses everything otherwise).
fn to_obvhs(r: &RayQuery) -> Ray {
    let d = Vec3A::from(r.d) + Vec3A::ZERO;
    Ray::new(r.o.into(), d, 0.0, r.tmax)
}

/// The fastest of `n` timed runs of `f`, with its result (the renders above are timed alike).
fn best_of(n: usize, mut f: impl FnMut() -> usize) -> (f64, usize) {
    let mut best = f64::INFINITY;
    let mut out = 0;
    for _ in 0..n {
        let t = Instant::now();
        out = std::hint::black_box(f());
        best = best.min(t.elapsed().as_secs_f64());
    }
    (best, out)
}
