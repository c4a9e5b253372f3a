//! `cell-list` (being written).
use super::{ForceKernel, ForceReport, KernelError, KernelKind};
use crate::physics::PairLaw;
use crate::real::Real;
use crate::state::{Field, State};
use std::marker::PhantomData;

pub struct CellList<L, T, const D: usize> {
    law: L,
    _t: PhantomData<T>,
}

impl<L: PairLaw<T>, T: Real, const D: usize> CellList<L, T, D> {
    pub fn new(law: L) -> Result<Self, KernelError> {
        Ok(CellList {
            law,
            _t: PhantomData,
        })
    }
}

impl<T: Real, L: PairLaw<T>, const D: usize> ForceKernel<T, D> for CellList<L, T, D> {
    fn kind(&self) -> KernelKind {
        KernelKind::CellList
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
