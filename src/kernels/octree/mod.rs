//! `octree` (being written).
use super::{ForceKernel, ForceReport, KernelKind};
use crate::physics::PairLaw;
use crate::real::Real;
use crate::state::{Field, State};
use std::marker::PhantomData;

pub struct Octree<L, T, const D: usize> {
    law: L,
    _t: PhantomData<T>,
}

impl<L, T: Real, const D: usize> Octree<L, T, D> {
    pub fn new(law: L, _theta: f64, _leaf_size: usize) -> Self {
        Octree {
            law,
            _t: PhantomData,
        }
    }
}

impl<T: Real, L: PairLaw<T>, const D: usize> ForceKernel<T, D> for Octree<L, T, D> {
    fn kind(&self) -> KernelKind {
        KernelKind::Octree
    }
    fn compute(
        &mut self,
        _state: &State<T, D>,
        _forces: &mut Field<T, D>,
        _probe: bool,
    ) -> ForceReport {
        let _ = &self.law;
        ForceReport::default()
    }
}
