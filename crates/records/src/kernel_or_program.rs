//! What a case measures: one of the built-in kernels, or a program declared in the sweep
//! config (`[[external]]`). Written in results files as the name alone (`"cell-list"`,
//! `"lammps"`), so a file reads the same whatever measured its cases, and the name is the
//! kernel name of case keys, tables and plots.

use nbody_engine::kernels::KernelKind;
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use std::fmt;

/// What a case measures: a built-in kernel or an `[[external]]` program, known by its name.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum KernelOrProgram {
    /// A kernel of this crate, measured in this process (or under the config's MPI launcher).
    Kernel(KernelKind),
    /// The `[[external]]` entry of this name: another program, run once per sample.
    External(String),
}

impl KernelOrProgram {
    /// The built-in kernel of this name, else the external program of that name (a config
    /// never gives an external a kernel's name).
    pub fn from_name(name: &str) -> KernelOrProgram {
        match KernelKind::ALL.iter().find(|k| k.name() == name) {
            Some(&k) => KernelOrProgram::Kernel(k),
            None => KernelOrProgram::External(name.to_string()),
        }
    }

    /// The name written in results files, case keys, tables and plots (`"cell-list"`, `"lammps"`).
    pub fn name(&self) -> &str {
        match self {
            KernelOrProgram::Kernel(k) => k.name(),
            KernelOrProgram::External(name) => name,
        }
    }

    /// The built-in kernel, `None` for an external program.
    pub fn kernel(&self) -> Option<KernelKind> {
        match self {
            KernelOrProgram::Kernel(k) => Some(*k),
            KernelOrProgram::External(_) => None,
        }
    }

    /// Whether the case runs an `[[external]]` program rather than a built-in kernel.
    pub fn is_external(&self) -> bool {
        matches!(self, KernelOrProgram::External(_))
    }

    /// Sort order: the built-in kernels in their declaration order, then the externals by name.
    pub fn order(&self) -> (u8, String) {
        match self {
            KernelOrProgram::Kernel(k) => (*k as u8, String::new()),
            KernelOrProgram::External(name) => (u8::MAX, name.clone()),
        }
    }
}

impl From<KernelKind> for KernelOrProgram {
    fn from(k: KernelKind) -> KernelOrProgram {
        KernelOrProgram::Kernel(k)
    }
}

impl PartialEq<KernelKind> for KernelOrProgram {
    fn eq(&self, other: &KernelKind) -> bool {
        self.kernel() == Some(*other)
    }
}

impl fmt::Display for KernelOrProgram {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl Serialize for KernelOrProgram {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

impl<'de> Deserialize<'de> for KernelOrProgram {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<KernelOrProgram, D::Error> {
        let name = String::deserialize(d)?;
        Ok(KernelOrProgram::from_name(&name))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_through_json() {
        for code in [
            KernelOrProgram::Kernel(KernelKind::CellList),
            KernelOrProgram::External("lammps".into()),
        ] {
            let text = serde_json::to_string(&code).unwrap();
            assert_eq!(text, format!("\"{}\"", code.name()));
            assert_eq!(
                serde_json::from_str::<KernelOrProgram>(&text).unwrap(),
                code
            );
        }
        assert_eq!(KernelOrProgram::from_name("octree"), KernelKind::Octree);
        assert!(KernelOrProgram::from_name("pytreegrav").is_external());
    }
}
