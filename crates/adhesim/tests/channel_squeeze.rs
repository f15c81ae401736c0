//! The shipped scenario scenarios/contact/channel-squeeze.toml: a soft tube squeezed until
//! its inner walls touch (self-contact on mortar sites), bonded, unloaded and pulled open.
//!
//! What it must show: the walls do not pass through each other (no site's gap below the
//! contact tolerance); the force against the plate's travel stiffens at touch-down (the
//! walls then carry load as well as the tube's bending); unloaded to zero plate force the
//! walls stay bonded (β > 0) and hold the channel shut; pulled further the bonds break, and
//! once every bond is gone the tube, elastic, gives the force it gave at the same travel on
//! the way down.

use adhesim::time::Stepper;
use adhesim_io::scenario::load;
use std::path::Path;
use std::sync::Arc;

/// One step's record: time [s], top plate travel [m], force of the plate on the tube [N] (upwards positive: the plate pulls),
/// bonded sites, contact sites and the smallest gap of a site in contact [m].
struct Row {
    t: f64,
    travel: f64,
    force: f64,
    bonded: usize,
    sites: usize,
    min_gap: f64,
}

fn run_channel() -> Vec<Row> {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/contact/channel-squeeze.toml");
    let problem = load(&path).unwrap_or_else(|e| panic!("{e}")).problem;
    let plate = problem
        .dirichlet
        .iter()
        .find(|d| d.components[1] && d.translation[1].v.iter().any(|&v| v != 0.0))
        .expect("the top plate's prescribed travel")
        .clone();
    let mut s = Stepper::new(Arc::new(problem)).expect("a valid scenario");
    let mut rows = Vec::new();
    while !s.finished() {
        s.step().unwrap_or_else(|e| panic!("{e:?}"));
        let f = s.disc.assemble(&s.state.u, false).force;
        let sites = &s.contact[0];
        rows.push(Row {
            t: s.state.t,
            travel: plate.translation[1].at(s.state.t),
            force: plate.nodes.iter().map(|&n| f[3 * n + 1]).sum(),
            bonded: sites.iter().filter(|c| c.history.bonded()).count(),
            sites: sites.iter().filter(|c| c.state >= 2).count(),
            min_gap: sites
                .iter()
                .filter(|c| c.gap.is_finite())
                .map(|c| c.gap)
                .fold(f64::INFINITY, f64::min),
        });
    }
    rows
}

/// Slope of the plate force against its travel [N/m] between rows `i` and `j`.
fn slope(rows: &[Row], i: usize, j: usize) -> f64 {
    (rows[j].force - rows[i].force) / (rows[j].travel - rows[i].travel)
}

#[test]
fn a_squeezed_channel_closes_bonds_its_walls_and_springs_open_when_pulled() {
    let rows = run_channel();
    let contact_tol = 1e-9;
    let min_gap = rows.iter().map(|r| r.min_gap).fold(f64::INFINITY, f64::min);
    eprintln!("smallest gap at a site {min_gap:.3e} m");
    assert!(min_gap > -contact_tol, "the walls pass through each other");

    // Touch-down: the first step with a site in contact, on the way down.
    let touch = rows
        .iter()
        .position(|r| r.sites > 0)
        .expect("the walls touch");
    let bottom = rows.iter().position(|r| r.t >= 1.0).unwrap();
    let (open_slope, closed_slope) = (slope(&rows, 0, touch / 2), slope(&rows, touch, bottom));
    eprintln!(
        "touch-down at {:.3} mm; slope {open_slope:.2} N/m before, {closed_slope:.2} N/m after",
        1e3 * rows[touch].travel
    );
    assert!(closed_slope > 3.0 * open_slope);

    // Unloading: the first step after the hold where the plate no longer pushes.
    let unloaded = rows
        .iter()
        .position(|r| r.t > 1.5 && r.force > 0.0)
        .expect("the plate force changes sign");
    let r = &rows[unloaded];
    eprintln!(
        "unloaded at {:.3} mm travel: {} sites bonded, {} in contact",
        1e3 * r.travel,
        r.bonded,
        r.sites
    );
    assert!(
        r.bonded > 0,
        "the walls let go when the plate stopped pushing"
    );

    // Pulled open: no bond left at the end, and the force of the open tube is the one it
    // had at the same travel on the way down (elastic, frictionless), to 1 %.
    let last = rows.last().unwrap();
    assert_eq!(last.bonded, 0);
    let broken = rows.iter().rposition(|r| r.bonded > 0).unwrap() + 1;
    let back = &rows[broken + (rows.len() - broken) / 4];
    let down = rows[..touch]
        .windows(2)
        .find(|w| (w[0].travel - back.travel) * (w[1].travel - back.travel) <= 0.0)
        .expect("the same travel on the way down");
    let a = (back.travel - down[0].travel) / (down[1].travel - down[0].travel);
    let force_down = down[0].force + a * (down[1].force - down[0].force);
    eprintln!(
        "bonds gone at {:.3} mm; at {:.3} mm: {:.6} N up, {force_down:.6} N down",
        1e3 * rows[broken].travel,
        1e3 * back.travel,
        back.force
    );
    assert!((back.force / force_down - 1.0).abs() < 0.01);
}
