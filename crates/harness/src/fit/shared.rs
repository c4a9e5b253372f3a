//! A scaling study measured on a shared machine. When other processes keep CPUs busy, the
//! workers of a parallel run time-share the CPUs with them: the run is slower than the code
//! makes it, and Amdahl's serial fraction, Karp-Flatt's e(p) and the efficiencies take that
//! in as if it were serial work or overhead. No reading of a scaling fit may then put the loss
//! of speedup on the code (its synchronisation, communication or memory contention); each says
//! the machine was shared instead. The calibration measures the load
//! (`Calibration::background_cpus`), and the threshold is the one the calibration and the gate
//! use ([`nbody_calibrate::SHARED_MACHINE_CPUS`]).

use serde::Serialize;

/// The other processes' load a study was measured under, when it makes the machine shared.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SharedMachine {
    /// CPUs' worth of time other processes used while the machine was calibrated (the larger
    /// of the sweep's start and end calibrations).
    pub background_cpus: f64,
}

impl SharedMachine {
    /// The shared machine of a study whose calibrations measured other processes using
    /// `background_cpus` (the most of any), or `None` when that is below the threshold or
    /// was not measured.
    pub fn of(background_cpus: Option<f64>) -> Option<SharedMachine> {
        background_cpus
            .filter(|&b| b >= nbody_calibrate::SHARED_MACHINE_CPUS)
            .map(|background_cpus| SharedMachine { background_cpus })
    }

    /// The sentence every scaling reading carries: "the machine was shared: other processes
    /// used 1.00 CPUs while it was calibrated, so …".
    pub fn sentence(&self) -> String {
        format!(
            "the machine was shared: other processes used {:.2} CPUs while it was calibrated, so \
             the workers time-shared the CPUs with them and the loss of speedup cannot be \
             attributed to the code",
            self.background_cpus
        )
    }

    /// The paragraph under a table whose readings are marked [`SharedMachine::MARK`].
    pub fn note(&self) -> String {
        format!(
            "{} = other processes used {:.2} CPUs while the machine was calibrated: the workers \
             time-shared the CPUs with them, so the speedups, efficiencies, serial fractions and \
             Karp-Flatt values marked so cannot be attributed to the code; measure again on a \
             quiet machine to read them as the code's.",
            Self::MARK,
            self.background_cpus
        )
    }

    /// What a table cell or a legend adds to a reading of this study.
    pub const MARK: &'static str = "shared machine";
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_calibration_threshold_decides_whether_a_machine_was_shared() {
        assert_eq!(SharedMachine::of(None), None);
        assert_eq!(SharedMachine::of(Some(0.1)), None);
        let busy = SharedMachine::of(Some(1.0)).unwrap();
        assert_eq!(busy.background_cpus, 1.0);
        assert!(SharedMachine::of(Some(nbody_calibrate::SHARED_MACHINE_CPUS)).is_some());
        let s = busy.sentence();
        assert!(s.contains("other processes used 1.00 CPUs"), "{s}");
        assert!(s.contains("cannot be attributed to the code"), "{s}");
    }
}
