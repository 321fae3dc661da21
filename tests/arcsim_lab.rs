//! The ARCSim round trip through the virtual laboratory (issue 38, part 2): each bundled
//! Wang–O'Brien–Ramamoorthi woven, imported, pulled along the warp, the weft and the bias
//! and bent along each at the sampled curvatures, reads the file's own values back, ARCSim's
//! model evaluated from its source: the warp and weft pulls within 3 % at 2 %, 8.3 % and
//! 16.7 % strain, the zero-strain bias modulus within 3 %, each direction's rigidity and the
//! warp's moments at 10–40 m⁻¹ within 2 % (up to where ARCSim's moment falls, and where
//! Rosette's free strip cannot relax through its bending coupling), the shear modulus within
//! 5 %. Only the held values are run here; `rosette fabric check NAME` reads everything, and
//! docs/fabric-sheets.md records what the projection drops.

use rosette::fabric::load_fabric;
use rosette::lab::ReadBack;
use rosette::lab::arcsim::{Scope, readback};

const WOVENS: [&str; 4] = ["11oz-black-denim", "royal-target", "white-dots-on-blk", "pink-ribbon-brown"];

/// Runs `work` on every item, two at a time (the machine's two cores).
fn on_two_cores<T: Sync, R: Send>(items: &[T], work: impl Fn(&T) -> R + Sync) -> Vec<R> {
    std::thread::scope(|s| {
        let halves = items.split_at(items.len().div_ceil(2));
        let work = &work;
        let a = s.spawn(move || halves.0.iter().map(work).collect::<Vec<_>>());
        let b: Vec<R> = halves.1.iter().map(work).collect();
        let mut out = a.join().unwrap();
        out.extend(b);
        out
    })
}

#[test]
fn bundled_arcsim_wovens_read_their_samples_back() {
    let results: Vec<ReadBack> = on_two_cores(&WOVENS, |name| {
        let f = load_fabric(name).unwrap();
        let started = std::time::Instant::now();
        let m = f.sheets.arcsim.as_ref().expect("an ARCSim fabric").material();
        let r = readback(&m, &f.config, Scope::Held).unwrap_or_else(|e| panic!("{name}: {e}"));
        println!("{name} ({:.1} s):\n{}", started.elapsed().as_secs_f64(), r.table());
        r
    });
    for (name, r) in WOVENS.iter().zip(&results) {
        let held = r.properties.iter().filter(|p| p.held()).count();
        // At least the six axis pulls, the bias modulus and the shear modulus.
        assert!(held >= 8, "{name}: only {held} values held");
        for p in r.properties.iter().filter(|p| p.held()) {
            assert!(p.passes(), "{name}: {} = {} {} in the file, {} read ({:+.2} %, tolerance {} %)", p.field, p.sheet, p.unit, p.measured, 100.0 * p.error(), 100.0 * p.tolerance);
        }
    }
}
