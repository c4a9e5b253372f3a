//! A scenario's initial state in formats other codes read (`nbody-bench export`), so that a
//! side-by-side case starts from the same particles:
//!
//! - `lammps-data`: a LAMMPS data file (atom style `atomic`) in LJ reduced units: lengths in σ,
//!   velocities in √(ε/m), one atom type of mass 1, the box of the walls (z from −0.5 to 0.5 in
//!   2-D). Lennard-Jones scenarios only.
//! - `text`: `# nbody-bench initial state v1`, a header with the scenario, the law's parameters,
//!   the box and the external field, then per particle `id x y [z] vx vy [vz] mass strength`
//!   in the scenario's own units.
//! - `npy`: the same columns as a little-endian float64 NumPy array of shape (n, columns).

use crate::boundary::Boundary;
use crate::geometry::Bounds;
use crate::kernels::CompiledKernels;
use crate::physics::{LawParameters, PairLaw};
use crate::real::Real;
use crate::scenario::{System, SystemJob};
use std::fmt::Write as _;
use thiserror::Error;

/// The file formats `nbody-bench export` writes (see the module doc).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum ExportFormat {
    /// A LAMMPS data file in LJ reduced units (Lennard-Jones scenarios only).
    LammpsData,
    /// The text format's columns as a little-endian float64 NumPy array.
    Npy,
    /// A commented header and one row per particle, which `run --initial` reads back.
    Text,
}

/// Why a state cannot be exported in the format asked.
#[derive(Debug, Error, PartialEq)]
pub enum ExportError {
    /// lammps-data for a scenario of another law: the scenario's name and its law's parameters.
    #[error(
        "the lammps-data format is for the Lennard-Jones scenarios (lj-box, lj-liquid, lj-gas, \
         lj-melt); scenario `{0}` has {1}: use --format text or npy"
    )]
    NotLj(&'static str, String),
    /// lammps-data with unequal masses, which one atom type cannot hold; holds a particle's index.
    #[error("lammps-data needs equal masses (one atom type); particle {0} has another mass")]
    Masses(usize),
}

/// The initial state of `setup` in `format` (not generic: see [`crate::run::run_setup`]).
pub fn export_setup(
    setup: &crate::scenario::Setup,
    format: ExportFormat,
) -> Result<Result<Vec<u8>, ExportError>, crate::scenario::SetupError> {
    setup.dispatch(ExportJob { format })
}

/// Writes the system's state in `format`.
pub(crate) struct ExportJob {
    pub format: ExportFormat,
}

impl SystemJob for ExportJob {
    type Output = Result<Vec<u8>, ExportError>;

    fn run<T: Real, L: CompiledKernels<T, D>, const D: usize>(
        self,
        system: System<T, L, D>,
    ) -> Self::Output {
        match self.format {
            ExportFormat::LammpsData => lammps_data(&system).map(String::into_bytes),
            ExportFormat::Text => Ok(text(&system).into_bytes()),
            ExportFormat::Npy => Ok(npy(&system)),
        }
    }
}

/// The first line of every header: what the state is.
fn describe<T: Real, L: PairLaw<T>, const D: usize>(s: &System<T, L, D>) -> String {
    format!(
        "scenario {} dim {D} precision {} n {} seed {} dt {}",
        s.info.scenario.name(),
        T::NAME,
        s.state.len(),
        s.info.seed,
        s.info.dt
    )
}

fn lammps_data<T: Real, L: PairLaw<T>, const D: usize>(
    s: &System<T, L, D>,
) -> Result<String, ExportError> {
    let LawParameters::LennardJones { epsilon, sigma, rc } = s.law.parameters() else {
        return Err(ExportError::NotLj(
            s.info.scenario.name(),
            s.law.parameters().to_string(),
        ));
    };
    let st = &s.state;
    let m = st.mass.first().map_or(1.0, |m| m.as_f64());
    if let Some(i) = st.mass.iter().position(|x| x.as_f64() != m) {
        return Err(ExportError::Masses(i));
    }
    let v_unit = (epsilon / m).sqrt();
    let (lo, hi) = match &s.boundary {
        Boundary::Reflecting { lo, hi } | Boundary::Periodic { lo, hi } => (
            lo.map(|x| x.as_f64() / sigma),
            hi.map(|x| x.as_f64() / sigma),
        ),
        Boundary::Open => {
            let Bounds { lo, hi } = st.bounding_box();
            (
                lo.map(|x| x.as_f64() / sigma - rc / sigma),
                hi.map(|x| x.as_f64() / sigma + rc / sigma),
            )
        }
    };
    let g = s.external.map(|a| a.as_f64() * sigma / (v_unit * v_unit));
    let mut out = String::with_capacity(st.len() * 64);
    let _ = writeln!(
        out,
        "LAMMPS data file from nbody-bench export: {}; reduced units: length sigma = {sigma}, \
         energy epsilon = {epsilon}, mass {m}, cutoff {} sigma, external acceleration {:?}",
        describe(s),
        rc / sigma,
        g
    );
    let _ = writeln!(out, "\n{} atoms\n1 atom types\n", st.len());
    for (d, axis) in ["x", "y", "z"].iter().enumerate() {
        let (a, b) = if d < D { (lo[d], hi[d]) } else { (-0.5, 0.5) };
        let _ = writeln!(out, "{a:e} {b:e} {axis}lo {axis}hi");
    }
    out.push_str("\nMasses\n\n1 1\n\nAtoms # atomic\n\n");
    let slots = st.slots_by_id();
    let coords = |field: &crate::state::Field<T, D>, slot: usize, unit: f64| {
        let mut c = String::new();
        for d in 0..3 {
            let x = if d < D {
                field[d][slot].as_f64() / unit
            } else {
                0.0
            };
            let _ = write!(c, " {x:e}");
        }
        c
    };
    for (id, &slot) in slots.iter().enumerate() {
        let _ = writeln!(out, "{} 1{}", id + 1, coords(&st.pos, slot, sigma));
    }
    out.push_str("\nVelocities\n\n");
    for (id, &slot) in slots.iter().enumerate() {
        let _ = writeln!(out, "{}{}", id + 1, coords(&st.vel, slot, v_unit));
    }
    Ok(out)
}

/// `id x y [z] vx vy [vz] mass strength` of every particle, in id order.
fn rows<T: Real, L, const D: usize>(s: &System<T, L, D>) -> Vec<Vec<f64>> {
    let st = &s.state;
    st.slots_by_id()
        .into_iter()
        .enumerate()
        .map(|(id, slot)| {
            let mut r = vec![id as f64];
            r.extend((0..D).map(|d| st.pos[d][slot].as_f64()));
            r.extend((0..D).map(|d| st.vel[d][slot].as_f64()));
            r.push(st.mass[slot].as_f64());
            r.push(st.source[slot].as_f64());
            r
        })
        .collect()
}

/// The column names of [`rows`].
pub fn columns(d: usize) -> String {
    let axes = &["x", "y", "z"][..d];
    let mut c = vec!["id".to_string()];
    c.extend(axes.iter().map(|a| a.to_string()));
    c.extend(axes.iter().map(|a| format!("v{a}")));
    c.extend(["mass".to_string(), "strength".to_string()]);
    c.join(" ")
}

fn text<T: Real, L: PairLaw<T>, const D: usize>(s: &System<T, L, D>) -> String {
    let mut out = String::from("# nbody-bench initial state v1\n");
    let _ = writeln!(out, "# {}", describe(s));
    let _ = writeln!(out, "# {}", s.law.parameters());
    match &s.boundary {
        Boundary::Reflecting { lo, hi } => {
            let _ = writeln!(
                out,
                "# box reflecting lo {:?} hi {:?}",
                lo.map(|x| x.as_f64()),
                hi.map(|x| x.as_f64())
            );
        }
        Boundary::Periodic { lo, hi } => {
            let _ = writeln!(
                out,
                "# box periodic lo {:?} hi {:?}",
                lo.map(|x| x.as_f64()),
                hi.map(|x| x.as_f64())
            );
        }
        Boundary::Open => out.push_str("# box open\n"),
    }
    let _ = writeln!(
        out,
        "# external acceleration {:?}",
        s.external.map(|a| a.as_f64())
    );
    let _ = writeln!(out, "# columns: {}", columns(D));
    let st = &s.state;
    for (id, slot) in st.slots_by_id().into_iter().enumerate() {
        let _ = write!(out, "{id}");
        for field in [&st.pos, &st.vel] {
            for d in 0..D {
                let _ = write!(out, " {:e}", field[d][slot]);
            }
        }
        let _ = writeln!(out, " {:e} {:e}", st.mass[slot], st.source[slot]);
    }
    out
}

fn npy<T: Real, L, const D: usize>(s: &System<T, L, D>) -> Vec<u8> {
    let rows = rows(s);
    let cols = 2 * D + 3;
    let mut header = format!(
        "{{'descr': '<f8', 'fortran_order': False, 'shape': ({}, {cols}), }}",
        rows.len()
    );
    // Magic (6) + version (2) + header length (2) + header, padded to 64 bytes with '\n' last.
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    let mut out = Vec::with_capacity(10 + header.len() + rows.len() * cols * 8);
    out.extend_from_slice(b"\x93NUMPY\x01\x00");
    out.extend_from_slice(&(header.len() as u16).to_le_bytes());
    out.extend_from_slice(header.as_bytes());
    for r in rows {
        for x in r {
            out.extend_from_slice(&x.to_le_bytes());
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::{ScenarioKind, Setup};

    #[test]
    fn npy_header_is_aligned_and_lammps_refuses_other_laws() {
        let mut setup = Setup::new(ScenarioKind::Galaxy);
        setup.n = Some(20);
        let bytes = setup
            .dispatch(ExportJob {
                format: ExportFormat::Npy,
            })
            .unwrap()
            .unwrap();
        let hlen = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
        assert_eq!((10 + hlen) % 64, 0);
        assert!(String::from_utf8_lossy(&bytes[10..10 + hlen]).contains("'shape': (20, 9)"));
        assert_eq!(bytes.len(), 10 + hlen + 20 * 9 * 8);
        let lammps = setup.dispatch(ExportJob {
            format: ExportFormat::LammpsData,
        });
        assert!(matches!(lammps, Ok(Err(ExportError::NotLj("galaxy", _)))));
    }
}
