//! Particles drawn in sorted order on the GPU: the sort by distance to the eye keeps alpha
//! blending back to front, spread over frames and behind an orbiting camera.

mod common;

use common::{context, no_gl_error};
use texflow::scene;

/// Per frame: distances to the eye of the live particles in drawing order, the number of live
/// particles in the state, and how many live ones lead the sorted texture before the first dead.
fn sorted_distances(
    name: &str,
    spread: Option<u32>,
    frames: usize,
) -> Vec<(Vec<f32>, usize, usize)> {
    let ctx = context();
    let mut s = scene::load(name).unwrap();
    s.particles.size = [16, 16];
    s.render.resolution = [64, 64];
    s.render.sort.passes_per_frame = spread;
    let mut e = texflow::ParticleEngine::new(&ctx, &s, 4).unwrap();
    let eye = e.camera().eye();
    let mut out = Vec::new();
    for _ in 0..frames {
        e.advance_frame().unwrap();
        e.draw().unwrap();
        let sorted = e.sorted().unwrap().texture(0).read_f32().unwrap();
        let live_in_state = e
            .sim()
            .read_positions()
            .unwrap()
            .chunks(4)
            .filter(|p| p[3] > 0.0)
            .count();
        let d: Vec<f32> = sorted
            .chunks(4)
            .filter(|p| p[3] > 0.0)
            .map(|p| glam::Vec3::new(p[0], p[1], p[2]).distance(eye))
            .collect();
        let prefix = sorted.chunks(4).take_while(|p| p[3] > 0.0).count();
        out.push((d, live_in_state, prefix));
    }
    no_gl_error(&ctx);
    out
}

/// Alpha blending draws back to front: after the GPU sort and gather, the live particles come
/// first (none lost or duplicated), farthest first; e3 sorts front to back.
#[test]
fn alpha_blending_draws_in_sorted_order() {
    for (name, descending) in [("smoke-unlit", true), ("e3", false)] {
        for (frame, (d, live, prefix)) in sorted_distances(name, None, 40).iter().enumerate() {
            assert_eq!(
                d.len(),
                *live,
                "{name} frame {frame}: live particles lost in the gather"
            );
            assert_eq!(
                prefix, live,
                "{name} frame {frame}: dead particles among the live"
            );
            for w in d.windows(2) {
                let ok = if descending {
                    w[0] >= w[1]
                } else {
                    w[0] <= w[1]
                };
                assert!(ok, "{name} frame {frame}: {} then {}", w[0], w[1]);
            }
        }
    }
}

/// Latta's sort spread over frames: with a few passes per frame the order is approximate but the
/// number of inversions stays far below that of an unsorted sequence, and no particle is lost.
#[test]
fn sort_spread_over_frames_keeps_most_of_the_order() {
    let frames = sorted_distances("smoke-unlit", Some(8), 60);
    let (d, live, _) = frames.last().unwrap();
    assert_eq!(d.len(), *live);
    let n = d.len();
    assert!(n > 50, "{n}");
    let inversions: usize = (0..n)
        .map(|i| (i + 1..n).filter(|&j| d[i] < d[j]).count())
        .sum();
    let pairs = n * (n - 1) / 2;
    // Random order has half the pairs inverted; the spread sort keeps well under 10%.
    assert!(
        inversions * 10 < pairs,
        "{inversions} inversions of {pairs} pairs"
    );
}

/// `render.camera.orbit` turns the camera with simulated time, and the whole sort follows it: the
/// drawing order is back to front from where the camera is now, not from where it started.
#[test]
fn orbiting_camera_is_followed_by_the_sort() {
    let ctx = context();
    let mut s = scene::load("smoke-unlit").unwrap();
    s.particles.size = [16, 16];
    s.render.resolution = [64, 64];
    s.render.camera.orbit = 90.0;
    let start = texflow::render::Camera::from(&s.render.camera);
    let mut e = texflow::ParticleEngine::new(&ctx, &s, 4).unwrap();
    let frames = 90;
    for _ in 0..frames {
        e.advance_frame().unwrap();
    }
    e.draw().unwrap();
    let t = e.sim().time();
    let expected_t = frames as f64 * s.time.dt as f64 * s.time.substeps as f64;
    assert!((t - expected_t).abs() < 1e-4, "{t} s simulated");
    let azimuth = e.camera().azimuth;
    assert!(
        (azimuth - (start.azimuth + 90.0 * t as f32)).abs() < 1e-3,
        "azimuth {azimuth} after {t} s"
    );
    let sorted = e.sorted().unwrap().texture(0).read_f32().unwrap();
    let live: Vec<glam::Vec3> = sorted
        .chunks(4)
        .filter(|p| p[3] > 0.0)
        .map(|p| glam::Vec3::new(p[0], p[1], p[2]))
        .collect();
    assert!(live.len() > 50, "{} live", live.len());
    let out_of_order = |eye: glam::Vec3| {
        live.windows(2)
            .filter(|w| w[0].distance(eye) < w[1].distance(eye))
            .count()
    };
    assert_eq!(
        out_of_order(e.camera().eye()),
        0,
        "not back to front from the camera"
    );
    assert!(
        out_of_order(start.eye()) > 0,
        "the order is still the one of the camera's start"
    );
    no_gl_error(&ctx);
}
