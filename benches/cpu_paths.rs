//! Criterion benches of the CPU paths: LOD generation, the schedule, the metrics oracle, CSV export.
//! `cargo bench --bench cpu_paths`

#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    reason = "a test or bench fails by panicking"
)]

use criterion::{criterion_group, criterion_main, Criterion};
use lodbench::geometry::lod::{LodChain, DEFAULT_TARGETS};
use lodbench::geometry::mesh::Mesh;
use lodbench::geometry::morph;
use lodbench::measure::metrics::SequenceMetrics;
use lodbench::measure::records::FrameRecord;
use lodbench::results::csv::FramesWriter;
use lodbench::rng::SplitMix64;
use lodbench::scene::schedule::{LodSchedule, ScheduleParams};
use lodbench::scene::BUNNY_OBJ;
use std::hint::black_box;

fn lod_generation(c: &mut Criterion) {
    let mesh = Mesh::parse_obj("bunny", BUNNY_OBJ).unwrap();
    c.bench_function("parse bunny OBJ", |b| {
        b.iter(|| Mesh::parse_obj("bunny", black_box(BUNNY_OBJ)).unwrap())
    });
    c.bench_function("bunny LOD chain 100/50/25/10 %", |b| {
        b.iter(|| LodChain::build("bunny", black_box(&mesh), &DEFAULT_TARGETS).unwrap())
    });
}

fn geomorph_correspondence(c: &mut Criterion) {
    let mesh = Mesh::parse_obj("bunny", BUNNY_OBJ).unwrap();
    let chain = LodChain::build("bunny", &mesh, &DEFAULT_TARGETS).unwrap();
    c.bench_function("geomorph nearest, all 3 bunny LOD pairs", |b| {
        b.iter(|| {
            for pair in chain.lods.windows(2) {
                black_box(morph::nearest_vertex(&pair[0].mesh, &pair[1].mesh));
            }
        })
    });
    c.bench_function("geomorph surface, all 3 bunny LOD pairs", |b| {
        b.iter(|| {
            for pair in chain.lods.windows(2) {
                black_box(morph::closest_surface(&pair[0].mesh, &pair[1].mesh));
            }
        })
    });
}

fn schedule(c: &mut Criterion) {
    let switches = [18.0f32, 37.0, 80.0];
    let n = 2000;
    let distances: Vec<f32> = (0..n).map(|i| 13.0 + i as f32 * 0.05).collect();
    c.bench_function("schedule update, 2000 instances", |b| {
        let mut s = LodSchedule::new(ScheduleParams::default(), n);
        b.iter(|| {
            let mut acc = 0.0;
            for (i, d) in distances.iter().enumerate() {
                acc += s.update(i, *d, &switches).k;
            }
            black_box(acc)
        })
    });
}

fn metrics_oracle(c: &mut Criterion) {
    let (w, h) = (800usize, 600usize);
    let mut rng = SplitMix64::new(3);
    let a: Vec<u8> = (0..w * h * 4)
        .map(|_| (rng.next_u64() & 255) as u8)
        .collect();
    let b: Vec<u8> = (0..w * h * 4)
        .map(|_| (rng.next_u64() & 255) as u8)
        .collect();
    c.bench_function("CPU rmse + pop, 800x600 frame", |bch| {
        let mut m = SequenceMetrics::new();
        bch.iter(|| black_box(m.frame(black_box(&a), black_box(&b))))
    });
}

fn csv_export(c: &mut Criterion) {
    let rows: Vec<FrameRecord> = (0..3600)
        .map(|f| FrameRecord {
            scene: "bunny-sweep".into(),
            method: "discrete".into(),
            count: 1,
            frame: f,
            gpu_ms: Some(1.0 + f as f64 * 1e-4),
            cpu_ms: 1.5,
            triangles: 3674,
            draw_calls: 1,
            units_drawn: 1,
            t_instances: 0,
            lod_mean: f as f64 / 1200.0,
            k_mean: None,
            rmse: Some(0.01),
            pop: Some(0.001),
            lodpop: Some(0.0),
            lodpop_coverage: None,
            lodpop_shading: None,
            de2000_mean: Some(0.1),
            uncovered_px: Some(0),
            crack_px: Some(0),
            flip_mean: None,
            combine_gpu_ms: None,
            lag_rmse: None,
            shadow_rmse: None,
            shadow_lodpop: None,
            splits: None,
            merges: None,
            select_cpu_ms: None,
            round: f / 360,
            fragments: None,
            view_pop: None,
        })
        .collect();
    let dir = tempfile::tempdir().unwrap();
    c.bench_function("frames.csv, 3600 rows", |b| {
        b.iter(|| {
            let mut w = FramesWriter::create(dir.path()).unwrap();
            w.write_block(black_box(&rows)).unwrap();
            w.finish().unwrap()
        })
    });
}

criterion_group!(
    benches,
    lod_generation,
    geomorph_correspondence,
    schedule,
    metrics_oracle,
    csv_export
);
criterion_main!(benches);
