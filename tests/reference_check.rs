//! Scratch
mod common;
use common::reference::*;

#[test]
fn dump() {
    for l in [0.0, 2.0, 8.0, 20.0, 100.0, 300.0, 1000.0, 3000.0, 1e4, 3e4, 1e5] {
        let t = std::time::Instant::now();
        let a = heavy_cantilever(l);
        let dt = t.elapsed();
        let b = heavy_cantilever_with_steps(l, 16000);
        println!("{l}: {:?} {} diff {:e} {:e} {:?}", a, a.tip_angle_rad.to_degrees(), (a.tip_drop_over_l-b.tip_drop_over_l).abs(), (a.tip_reach_over_l-b.tip_reach_over_l).abs(), dt);
    }
}
