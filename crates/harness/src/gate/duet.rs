//! Duet measurement: both sides of an A/B round at the same moment, each pinned to a CPU of
//! its own, the CPUs swapped every round (Bulej et al., ICPE 2020). Whatever the machine does
//! during the round (a frequency change, a neighbour's burst on the host) falls on both sides,
//! so the round's ratio cancels it; sides taking turns on one CPU see it only when it lasts
//! longer than a round.

use std::process::Command;

/// How the two sides of an A/B round share the machine.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize, clap::ValueEnum,
)]
#[serde(rename_all = "kebab-case")]
pub enum Sides {
    /// Both sides at once, one per CPU, swapped every round.
    Duet,
    /// One side after the other, the first alternating.
    Turns,
}

impl Sides {
    /// "duet" or "turns", as the reports name it.
    pub fn name(self) -> &'static str {
        match self {
            Sides::Duet => "duet",
            Sides::Turns => "turns",
        }
    }
}

/// The two CPUs a duet runs on: the first two this process may run on (none with fewer).
pub fn cpus() -> Option<[usize; 2]> {
    let allowed = allowed_cpus();
    (allowed.len() >= 2).then(|| [allowed[0], allowed[1]])
}

/// The CPUs this process may run on, in order.
fn allowed_cpus() -> Vec<usize> {
    // SAFETY: `set` is a plain bit set the call fills in; the size passed is its own.
    unsafe {
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        if libc::sched_getaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &mut set) != 0 {
            return Vec::new();
        }
        (0..libc::CPU_SETSIZE as usize)
            .filter(|&c| libc::CPU_ISSET(c, &set))
            .collect()
    }
}

/// The sides' way for an A/B run, with why when it is not the one asked for: `turns` as asked;
/// `duet` as asked wherever this process may use two CPUs; by default duet on a machine with
/// two CPUs free for it, else turns. `background_cpus`: the CPUs other processes used while
/// the machine was calibrated. Beside such a process two sides at once would share the CPUs
/// with it unevenly, where one side at a time leaves it the other CPU.
pub fn choose(requested: Option<Sides>, background_cpus: Option<f64>) -> (Sides, Option<String>) {
    let busy = background_cpus.filter(|&b| b >= super::BUSY_BASELINE_CPUS);
    match (requested, busy) {
        (Some(Sides::Turns), _) => (Sides::Turns, None),
        _ if cpus().is_none() => (
            Sides::Turns,
            Some("this process may run on one CPU only: the builds take turns".to_string()),
        ),
        (None, Some(busy)) => (
            Sides::Turns,
            Some(format!(
                "other processes used {busy:.1} CPUs while the gate calibrated: the builds take \
                 turns rather than share both CPUs with them (--sides duet to measure at once)"
            )),
        ),
        _ => (Sides::Duet, None),
    }
}

/// Whether a duet may measure `case`: one thread, one rank, a built-in kernel. Pinned to one
/// CPU, a case of more workers would run them in turns, and an external program may start
/// workers of its own; such cases take turns in every mode.
pub fn suits(case: &nbody_records::plan::Case) -> bool {
    case.threads == 1
        && case.ranks == 1
        && matches!(
            case.kernel,
            nbody_records::kernel_or_program::KernelOrProgram::Kernel(_)
        )
}

/// Makes the process `command` starts run on `cpu` only (and the threads it starts, which
/// inherit the mask).
pub fn pin_command(command: &mut Command, cpu: usize) {
    use std::os::unix::process::CommandExt;
    // SAFETY: the closure runs between fork and exec; it only fills a stack bit set and makes
    // one system call, both async-signal-safe.
    unsafe {
        command.pre_exec(move || {
            if pin(cpu) {
                Ok(())
            } else {
                Err(std::io::Error::last_os_error())
            }
        });
    }
}

/// Makes the calling thread run on `cpu` only; false if the kernel refused.
pub fn pin_this_thread(cpu: usize) -> bool {
    pin(cpu)
}

fn pin(cpu: usize) -> bool {
    // SAFETY: `set` is a plain bit set on the stack; the size passed is its own.
    unsafe {
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        libc::CPU_SET(cpu, &mut set);
        libc::sched_setaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &set) == 0
    }
}

/// The CPU (index into [`cpus`]) side `side` (0 or 1) runs on in round `round` of a duet: the
/// sides swap CPUs every round, so that each has each CPU as often.
pub fn cpu_of(side: usize, round: usize) -> usize {
    (side + round) % 2
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_thread_pinned_runs_where_it_was_put() {
        let Some([_, second]) = cpus() else {
            return;
        };
        let ran_on = std::thread::spawn(move || {
            assert!(pin_this_thread(second));
            // SAFETY: sched_getcpu has no arguments and no preconditions.
            unsafe { libc::sched_getcpu() }
        })
        .join()
        .unwrap();
        assert_eq!(ran_on, second as i32);
    }

    #[test]
    fn a_pinned_child_may_run_on_its_cpu_only() {
        let Some([first, _]) = cpus() else {
            return;
        };
        let mut command = Command::new("sh");
        command.args(["-c", "grep Cpus_allowed_list /proc/self/status"]);
        pin_command(&mut command, first);
        let out = command.output().unwrap();
        let text = String::from_utf8_lossy(&out.stdout);
        assert_eq!(
            text.split_whitespace().last(),
            Some(first.to_string().as_str())
        );
    }

    #[test]
    fn turns_when_asked_for_or_by_default_on_a_busy_machine() {
        assert_eq!(choose(Some(Sides::Turns), None), (Sides::Turns, None));
        let (sides, why) = choose(None, Some(1.0));
        assert_eq!(sides, Sides::Turns);
        assert!(why.is_some());
        if cpus().is_some() {
            assert_eq!(choose(None, Some(0.1)), (Sides::Duet, None));
            assert_eq!(choose(Some(Sides::Duet), Some(1.0)), (Sides::Duet, None));
        }
    }

    #[test]
    fn only_one_worker_cases_of_built_in_kernels_suit_a_duet() {
        let text = "name = \"t\"\nstudy = \"cartesian\"\nscenarios = [\"lj-box\"]\n\
                    kernels = [\"cell-list\"]\nn = [500]\nthreads = [1, 2]\n";
        let config =
            nbody_records::config::SweepConfig::parse(text, std::path::Path::new("t.toml"))
                .unwrap();
        let cases = nbody_records::plan::cases(&config);
        let suited: Vec<usize> = cases
            .iter()
            .filter(|c| suits(c))
            .map(|c| c.threads)
            .collect();
        assert_eq!(suited, [1]);
        assert_eq!(cases.len(), 2);
    }

    #[test]
    fn the_sides_swap_cpus_every_round() {
        for round in 0..6 {
            assert_ne!(cpu_of(0, round), cpu_of(1, round));
            assert_ne!(cpu_of(0, round), cpu_of(0, round + 1));
        }
        let on_first = (0..4).filter(|&r| cpu_of(0, r) == 0).count();
        assert_eq!(on_first, 2);
    }
}
