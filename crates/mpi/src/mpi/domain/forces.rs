//! Forces in the domain decomposition, overlapping the ghost exchange with computation.
//!
//! A particle within the ghost width `w` (the cutoff) of a neighbour's region is a *border*
//! particle: a copy goes to that neighbour as a ghost, and its own force needs the neighbour's
//! ghosts. The forces of all owned particles from the owned particles are computed while the
//! ghost messages travel; that is the final force of every particle but the border ones. Then
//! the border particles get their forces again from a small system: themselves, the owned
//! particles within `2w` of a neighbour (all their owned partners within the cutoff), and the
//! ghosts (all their foreign partners).

use super::Domain;
use crate::decomp::regions::point_box_distance2;
use crate::decomp::wire::{bytes_of, push_source, unpack_sources};
use crate::mpi::communicator::Comm;
use crate::mpi::driver::TAG_GHOSTS;
use crate::mpi::error::MpiError;
use crate::real::Real;
use crate::state::zero_field;
use std::time::Instant;

impl<T: Real, const D: usize> Domain<T, D> {
    /// Overwrites the forces of the owned particles.
    pub(super) fn compute_forces(&mut self, comm: &mut Comm) -> Result<(), MpiError> {
        let t = Instant::now();
        let ghosts = self.classify();
        let bytes: Vec<Vec<u8>> = ghosts.iter().map(|g| bytes_of(g).to_vec()).collect();
        let mut force_s = t.elapsed().as_secs_f64();
        let (interior, owned, forces) = (&mut self.interior, &self.owned, &mut self.forces);
        let (arrived, report) =
            comm.exchange_overlapped(&self.neighbours, &bytes, TAG_GHOSTS, || {
                let t = Instant::now();
                let report = interior.compute(owned, forces, false);
                (report, t.elapsed().as_secs_f64())
            })?;
        let (report, interior_s) = report;
        force_s += interior_s;
        self.tally.work += report.work;
        self.tally.build_s += report.build_s;

        let t = Instant::now();
        let received = self.fill_shell(&arrived);
        self.tally.ghosts_received += received as u64;
        let b = self.border_slots.len();
        if b > 0 && received > 0 {
            if self.border_forces[0].len() < b {
                self.border_forces = zero_field(b);
            }
            let out = self.border_forces.each_mut().map(|f| &mut f[..b]);
            let report = self.border.compute_targets(&self.shell, 0..b, out);
            self.tally.work += report.work;
            self.tally.build_s += report.build_s;
            for (k, &i) in self.border_slots.iter().enumerate() {
                for d in 0..D {
                    self.forces[d][i] = self.border_forces[d][k];
                }
            }
        }
        self.tally.force_s += force_s + t.elapsed().as_secs_f64();
        Ok(())
    }

    /// Finds the border particles (`border_slots`) and the other owned particles within `2w`
    /// of a neighbour (`shell_slots`); returns the ghosts for each neighbour: coordinates and
    /// source strength per particle.
    fn classify(&mut self) -> Vec<Vec<T>> {
        let w = self.width;
        let (lo, hi) = self.regions.region(self.me);
        let boxes: Vec<([f64; D], [f64; D])> = self
            .neighbours
            .iter()
            .map(|&r| self.regions.region(r))
            .collect();
        let mut ghosts = vec![Vec::new(); boxes.len()];
        self.border_slots.clear();
        self.shell_slots.clear();
        if boxes.is_empty() {
            return ghosts;
        }
        for i in 0..self.owned.len() {
            let x = self.owned.position(i).map(|v| v.as_f64());
            // Deeper than 2w inside the region: no neighbour is that close.
            if (0..D).all(|d| x[d] > lo[d] + 2.0 * w && x[d] < hi[d] - 2.0 * w) {
                continue;
            }
            let mut nearest = f64::INFINITY;
            for (k, (l, h)) in boxes.iter().enumerate() {
                let d2 = point_box_distance2(&x, l, h);
                if d2 < w * w {
                    ghosts[k].extend(self.owned.position(i));
                    ghosts[k].push(self.owned.source[i]);
                }
                nearest = nearest.min(d2);
            }
            if nearest < w * w {
                self.border_slots.push(i);
            } else if nearest < 4.0 * w * w {
                self.shell_slots.push(i);
            }
        }
        ghosts
    }

    /// Lays out the border system: border particles first (the targets), then the shell, then
    /// the ghosts that arrived. Returns the number of ghosts.
    fn fill_shell(&mut self, arrived: &[Vec<u8>]) -> usize {
        let s = &mut self.shell;
        for d in 0..D {
            s.pos[d].clear();
            s.vel[d].clear();
        }
        s.mass.clear();
        s.source.clear();
        s.id.clear();
        let owned = &self.owned;
        for &i in self.border_slots.iter().chain(&self.shell_slots) {
            push_source(s, owned.position(i), owned.source[i], owned.id[i]);
        }
        let mut ghosts = 0;
        for bytes in arrived {
            ghosts += unpack_sources(bytes, s);
        }
        ghosts
    }
}
