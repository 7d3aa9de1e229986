//! The work-precision table of docs/integrators.md: every method at rtol
//! 1e-4 … 1e-10 on the reference problems of the stepper tests, with steps,
//! rejections, right-hand-side calls, Jacobians, LU factorisations and the
//! error against the exact or published solution.
//!
//! cargo run --release --example work_precision_table

#[path = "../tests/it/ode_problems.rs"]
mod ode_problems;

use autobal::integrate::{Method, NoObserver, SolverOptions, Status, solve};
use ode_problems::{max_rel_error, problems};

fn main() {
    for p in problems() {
        println!("\n{}\n", p.name);
        println!("| method | rtol | steps | rejected | RHS calls | Jacobians | LUs | error |");
        println!("| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: |");
        let reference = (p.reference)();
        for &m in Method::ALL {
            for tol in [1e-4, 1e-6, 1e-8, 1e-10] {
                let o = SolverOptions {
                    rtol: tol,
                    atol: p.atol_scale.iter().map(|s| s * tol).collect(),
                    ..SolverOptions::default()
                };
                let r = solve(m, p.system, 0.0, p.y0, p.t_end, &o, &mut NoObserver);
                if r.status != Status::Finished {
                    println!("| {} | {tol:.0e} | {:?} | | | | | |", m.name(), r.status);
                    continue;
                }
                let err = max_rel_error(&r.y, &reference, p.error_floor);
                let s = r.stats;
                println!(
                    "| {} | {tol:.0e} | {} | {} | {} | {} | {} | {err:.1e} |",
                    m.name(),
                    s.steps,
                    s.rejected,
                    s.rhs_calls,
                    s.jacobians,
                    s.factorizations
                );
            }
        }
    }
}
