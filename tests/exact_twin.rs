//! The exact mode's response against a twin written from the equations of docs/collisions.md
//! ("The exact mode's response, in full"), independently of src/sim/reference: a moving gas of
//! particles of different masses, one iteration per step, every particle's position and velocity
//! after the response pass against the twin's from the state that pass read.

mod common;

use common::context;
use common::scene::random_gas;
use glam::DVec3;
use texflow::sim::ParticleSim;

const R: f64 = 0.04;
const E: f64 = 0.6;
const DT: f64 = 0.01;
const MASS: [f64; 2] = [0.5, 8.0];

fn gas_scene() -> texflow::scene::SceneFile {
    let src = format!(
        "name = \"twin\"\nintegrator = \"euler\"\n[particles]\nsize = [16, 16]\n[time]\n\
         dt = {DT}\n[[emitters.initial]]\ndirection = [0.0, 1.0, 0.0]\nspeed = [0.0, 0.0]\n\
         mass_range = [{}, {}]\n[collisions]\nradius = {R}\nrestitution = {E}\n\
         detection = \"exact\"\niterations = 1\nbounds = [[-2.0, -2.0, -2.0], [3.0, 3.0, 3.0]]\n",
        MASS[0], MASS[1]
    );
    common::scene::parse("twin", &src)
}

/// One particle as the response pass reads it.
#[derive(Clone, Copy)]
struct P {
    x: DVec3,
    v: DVec3,
    m: f64,
    h: f64,
}

/// The documented response of one pass, all particles at once (the equations of
/// docs/collisions.md, numbered as there).
fn twin(ps: &[P]) -> Vec<(DVec3, DVec3)> {
    let reach = 2.0 * R;
    // (1) partners and their count.
    let partners: Vec<Vec<usize>> = (0..ps.len())
        .map(|i| {
            (0..ps.len())
                .filter(|&j| j != i && (ps[i].x - ps[j].x).length_squared() < reach * reach)
                .collect()
        })
        .collect();
    // The closest partner that i approaches.
    let closest: Vec<Option<usize>> = (0..ps.len())
        .map(|i| {
            let d = |j: &&usize| (ps[i].x - ps[**j].x).length_squared();
            let approaching = |j: &&usize| (ps[i].x - ps[**j].x).dot(ps[i].v - ps[**j].v) < 0.0;
            (partners[i].iter().filter(approaching))
                .min_by(|a, b| d(a).total_cmp(&d(b)))
                .copied()
        })
        .collect();
    (0..ps.len())
        .map(|i| {
            let (a, mut dx_i, mut dv_i) = (ps[i], DVec3::ZERO, DVec3::ZERO);
            for &j in &partners[i] {
                let b = ps[j];
                // (2) back to first contact.
                let (dx, dv) = (a.x - b.x, a.v - b.v);
                let c = dx.length_squared() - reach * reach;
                let (vv, xv) = (dv.length_squared(), dx.dot(dv));
                let tau = if vv > 0.0 {
                    ((xv + (xv * xv - vv * c).max(0.0).sqrt()) / vv).clamp(0.0, DT)
                } else {
                    0.0
                };
                let xc = dx - dv * tau;
                let nrm = if xc.length() > 0.0 {
                    xc.normalize()
                } else {
                    DVec3::new(0.0, if a.h < b.h { 1.0 } else { -1.0 }, 0.0)
                };
                // (3) the exchange, with the matched pairs only.
                let matched = closest[i] == Some(j) && closest[j] == Some(i);
                let vn = dv.dot(nrm);
                let (mut ai, mut aj) = (DVec3::ZERO, DVec3::ZERO);
                if matched && vn < 0.0 {
                    ai = -(1.0 + E) * b.m / (a.m + b.m) * vn * nrm;
                    aj = (1.0 + E) * a.m / (a.m + b.m) * vn * nrm;
                }
                // (4) the separation of what still overlaps.
                let sep = dx + (ai - aj) * tau;
                let depth = reach - sep.length();
                if depth > 0.0 {
                    dx_i += b.m / (a.m + b.m) * depth * sep.normalize();
                }
                dv_i += ai;
                dx_i += ai * tau;
            }
            (a.x + dx_i, a.v + dv_i)
        })
        .collect()
}

/// A moving gas with masses from 0.5 to 8 kg, about two overlapping neighbours per particle,
/// relative speeds up to about 5 m/s, 4 steps of one iteration: every particle's velocity after
/// the response pass equals the twin's to 1e-5 m/s and its position to 1e-6 m.
#[test]
fn exact_response_matches_the_documented_equations() {
    let ctx = context();
    let s = gas_scene();
    let mut sim = ParticleSim::new(&ctx, &s, 1).unwrap();
    // Random numbers whose fract(4096 r) spreads the masses over the range.
    common::set_particles(&mut sim, &random_gas(256, 11, 6.0, 0.55), |i, _| {
        ((i as f32 + 0.5) * 0.618034).fract()
    });
    sim.collisions_mut().unwrap().record_iterations(true);
    let (mut worst_v, mut worst_x, mut exchanges) = (0.0f64, 0.0f64, 0);
    for step in 0..4 {
        sim.step().unwrap();
        let rec = &sim.collisions().unwrap().recorded()[0];
        // The statics in the same sorted order: type and random number, hence the mass.
        let st = sim.statics().read_f32().unwrap();
        let (x1, v1) = (
            sim.read_positions().unwrap(),
            sim.read_velocities().unwrap(),
        );
        let live: Vec<usize> = (0..256)
            .filter(|&k| rec.positions[k * 4 + 3] > 0.0)
            .collect();
        assert_eq!(live.len(), 256);
        let d3 = |a: &[f32], k: usize| {
            DVec3::new(a[k * 4] as f64, a[k * 4 + 1] as f64, a[k * 4 + 2] as f64)
        };
        let ps: Vec<P> = live
            .iter()
            .map(|&k| {
                let f = (4096.0 * st[k * 4 + 3]).fract() as f64;
                P {
                    x: d3(&rec.positions, k),
                    v: d3(&rec.velocities, k),
                    m: MASS[0] * (1.0 - f) + MASS[1] * f,
                    h: st[k * 4 + 3] as f64,
                }
            })
            .collect();
        let out = twin(&ps);
        for (q, &k) in live.iter().enumerate() {
            let (x, v) = out[q];
            let (ev, ex) = (
                (d3(&v1, k) - v).abs().max_element(),
                (d3(&x1, k) - x).abs().max_element(),
            );
            if (v - ps[q].v).length() > 1e-3 {
                exchanges += 1;
            }
            assert!(
                ev <= 1e-5 && ex <= 1e-6,
                "step {step}, texel {k}: GPU {} {} vs twin {x} {v}",
                d3(&x1, k),
                d3(&v1, k)
            );
            worst_v = worst_v.max(ev);
            worst_x = worst_x.max(ex);
        }
    }
    eprintln!("worst: velocity {worst_v:e} m/s, position {worst_x:e} m; {exchanges} exchanges");
    assert!(exchanges > 50, "too few exchanges to test: {exchanges}");
}
