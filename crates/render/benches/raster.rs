//! Rasterizer benchmark: a ~14k-triangle sphere and the Spot cow at 400×400.
//!
//! Run: `cargo bench -p toonkit-render --bench raster`.

// `criterion_group!` generates an undocumented `pub fn`.
#![allow(missing_docs)]

use criterion::{criterion_group, criterion_main, Criterion};
use glam::Vec3;
use render::{ColorMap, DrawList, MeshColors, MeshItem, Renderer, View, ViewDirection};

/// A UV sphere with `rings × segments` quads (2 triangles each, poles as fans).
fn sphere(rings: u32, segments: u32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let mut p = Vec::new();
    for i in 0..=rings {
        let th = std::f32::consts::PI * i as f32 / rings as f32;
        for j in 0..segments {
            let ph = std::f32::consts::TAU * j as f32 / segments as f32;
            p.push(Vec3::new(
                th.sin() * ph.cos(),
                th.cos(),
                th.sin() * ph.sin(),
            ));
        }
    }
    let mut t = Vec::new();
    for i in 0..rings {
        for j in 0..segments {
            let a = i * segments + j;
            let b = i * segments + (j + 1) % segments;
            let (c, d) = (a + segments, b + segments);
            if i > 0 {
                t.push([a, b, c]);
            }
            if i + 1 < rings {
                t.push([b, d, c]);
            }
        }
    }
    (p, t)
}

/// Process CPU time (user + system, all threads) in seconds, from /proc/self/stat (Linux);
/// 0 elsewhere. On a shared machine this is steadier than wall time.
fn cpu_seconds() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else {
        return 0.0;
    };
    let Some(rest) = stat.rsplit(')').next() else {
        return 0.0;
    };
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |i: usize| f.get(i).and_then(|v| v.parse::<f64>().ok()).unwrap_or(0.0);
    // Fields 14 and 15 of the file (utime, stime) are 12 and 13 after the command name.
    (ticks(11) + ticks(12)) / 100.0
}

/// Prints wall and CPU milliseconds per call of `f` over `n` calls.
fn report_cpu(name: &str, n: usize, mut f: impl FnMut()) {
    let (t0, c0) = (std::time::Instant::now(), cpu_seconds());
    for _ in 0..n {
        f();
    }
    let wall = t0.elapsed().as_secs_f64() / n as f64 * 1e3;
    let cpu = (cpu_seconds() - c0) / n as f64 * 1e3;
    eprintln!("{name}: wall {wall:.2} ms, cpu {cpu:.2} ms per render ({n} renders)");
}

fn bench(c: &mut Criterion) {
    let (p, t) = sphere(60, 120);
    let values: Vec<f32> = p.iter().map(|q| q.x).collect();
    let colors = ColorMap::Diverging.colors(&values);
    let r = Renderer::new(400, 400).unwrap();
    let list = DrawList::new().mesh(MeshItem::new(&p, &t).colors(MeshColors::PerVertex(&colors)));
    let view = View::fit(list.bbox(), ViewDirection::ThreeQuarter, 1.0);
    eprintln!("sphere: {} triangles", t.len());
    report_cpu("sphere_14k_400x400", 300, || {
        r.render(&list, &view).unwrap();
    });
    c.bench_function("sphere_14k_400x400", |b| {
        b.iter(|| r.render(&list, &view).unwrap())
    });
    let translucent = DrawList::new().mesh(MeshItem::new(&p, &t).opacity(0.5));
    c.bench_function("sphere_14k_400x400_translucent", |b| {
        b.iter(|| r.render(&translucent, &view).unwrap())
    });
    let mut o = render::RenderOptions::new(400, 400);
    o.supersample = 2;
    let r2 = Renderer::with_options(o).unwrap();
    c.bench_function("sphere_14k_400x400_ssaa2", |b| {
        b.iter(|| r2.render(&list, &view).unwrap())
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
