//! Bad input, bounded work (issue 12): results that do not depend on the units of the
//! stiffness, and no non-finite number written.

use spira::case::Case;
use spira::run::run_path;
use std::path::Path;

fn thesis_n1() -> Case {
    Case::from_file(&Path::new(env!("CARGO_MANIFEST_DIR")).join("cases/thesis-n1.toml"))
        .expect("shipped case")
}

#[test]
fn every_stiffness_times_1e5_gives_the_thesis_n1_path_scaled_by_1e5() {
    let case = thesis_n1();
    let mut stiff = case.clone();
    let s = 1e5;
    stiff = Case {
        stiffness: spira::model::stiffness::Stiffness {
            b1: case.stiffness.b1 * s,
            b2: case.stiffness.b2 * s,
            b3: case.stiffness.b3 * s,
        },
        ..stiff
    };
    stiff.solver.newton.force_scale = stiff.stiffness.b1;
    // the case file says the same
    let text = "[stiffness]\nb1 = 1e5\nb2 = 1e5\nb3 = 2e5\n";
    let parsed = Case::parse(text, "stiff.toml", "thesis-n1").expect("valid");
    assert_eq!(parsed.solver.newton.force_scale, 1e5);
    assert_eq!(parsed.stiffness, stiff.stiffness);

    let eps = case.output_eps(case.loading.target, case.loading.steps);
    let a = run_path(&case, &eps, |_, _| {}).expect("thesis n = 1");
    let b = run_path(&stiff, &eps, |_, _| {}).expect("thesis n = 1, stiffness x 1e5");
    assert!(
        a.error.is_none() && b.error.is_none(),
        "{:?} {:?}",
        a.error,
        b.error
    );
    assert_eq!(a.points.len(), b.points.len());
    let rel = |x: f64, y: f64, scale: f64| (x - y).abs() / scale;
    for (p, q) in a.points.iter().zip(&b.points) {
        assert_eq!(p.eps, q.eps);
        // normalised by n Pcrit: the same numbers
        for k in 0..3 {
            assert!(
                rel(p.load[k], q.load[k], 1.0) < 1e-7,
                "step {}: {:?} vs {:?}",
                p.step,
                p.load,
                q.load
            );
        }
        let e_scale = p.energy.abs().max(1e-6);
        assert!(
            rel(p.energy * s, q.energy, e_scale * s) < 1e-7,
            "energy {} vs {}",
            p.energy,
            q.energy
        );
        for (ra, rb) in p.reactions.iter().zip(&q.reactions) {
            for k in 0..3 {
                let f = ra.tip.force.iter().map(|v| v.abs()).fold(1e-3, f64::max);
                assert!(rel(ra.tip.force[k] * s, rb.tip.force[k], f * s) < 1e-7);
            }
        }
        assert_eq!(
            p.stability.map(|x| x.unstable_directions),
            q.stability.map(|x| x.unstable_directions)
        );
    }
    let (last_a, last_b) = (a.points.last().unwrap(), b.points.last().unwrap());
    assert!((last_a.load[2] - -3.082).abs() < 1e-3, "{}", last_a.load[2]);
    assert!((last_b.load[2] - last_a.load[2]).abs() < 1e-7);
}

#[test]
fn writers_refuse_non_finite_cells_naming_the_column() {
    use spira::output::check_finite;
    assert!(check_finite("# case\nstep,fz\n0,1.0e0\n").is_ok());
    for bad in ["NaN", "inf", "-inf"] {
        let e = check_finite(&format!(
            "# case\nstep,fz,energy\n0,1.0e0,2.0e0\n1,3.0e0,{bad}\n"
        ))
        .expect_err("a non-finite cell");
        assert_eq!(e.column, "energy");
        assert_eq!(e.row, 2);
        assert!(e.to_string().contains("column `energy`"), "{e}");
    }
    // names are not numbers
    assert!(check_finite("rod,kind\n0,information\n").is_ok());
}
