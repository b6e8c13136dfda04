use geosens::rod::{Direction, Method, Probe, Rod, exact};
use geosens::{RunConfig, run};
fn main() {
    for (ks, ke) in [(0.07, 0.1), (2.1, 3.0)] {
        let rod = Rod::new(ks, ke, 2.0).unwrap();
        for x in [0.0, 1.0, 1.9, 2.0] {
            for om in [Direction::Right, Direction::Left] {
                let p = Probe::new(&rod, x, om).unwrap();
                let ex = exact::solve(&rod, x, om);
                print!(
                    "ks={ks} x={x} {om:?} exact I={:.5} s={:.5} dx={:.5} |",
                    ex.intensity, ex.sensitivity, ex.gradient_x
                );
                for m in Method::ALL {
                    let r = run(
                        m.estimator(rod, p).as_ref(),
                        &RunConfig::new(1_000_000, 1).unwrap(),
                    )
                    .unwrap();
                    for (q, e) in &r.estimates {
                        print!(" {}:{q}={:.5}±{:.5}", m.name(), e.mean, e.stderr);
                    }
                }
                println!();
            }
        }
    }
}
