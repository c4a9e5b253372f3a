//! The files a sweep is defined by and leaves behind, and their versions: the sweep config
//! (`config`; each key's doc comment becomes its parse messages in `config_keys` and its row of
//! the reference page in `config_reference`; the external programs' entries in `external`), the
//! cases it plans (`plan`, each measuring a `kernel_or_program`), the results file with every
//! round (`results`, `round`, the outlier rules of `vet`), the batch system's table and job
//! records (`scheduler`) and the run directories (`locate`). The runner (`experiment` in the
//! harness) writes them and `analysis` reads them; neither needs the other.

pub mod config;
pub mod config_keys;
pub mod config_reference;
pub mod external;
pub mod kernel_or_program;
pub mod locate;
pub mod plan;
pub mod results;
pub mod round;
pub mod scheduler;
pub mod tidy;
pub mod vet;
