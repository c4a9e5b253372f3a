//! Child programs run in process groups of their own, and the registry of those groups.
//!
//! A program we start may start others (`sh -c "sleep 43; echo"`, `mpirun` and its ranks).
//! Signalling only the direct child leaves the rest running, so each program is started as
//! the leader of a new process group and every signal goes to the whole group: at a timeout,
//! after the program ends (members it left behind), and when this process is interrupted
//! (SIGINT, SIGTERM), where the interrupt handler calls [`stop_all`] for the groups still
//! running. A program that leaves its group on purpose (`setsid`, a daemon) is out of reach.

pub mod supervised;

use std::process::{Child, Command};
use std::sync::{Mutex, MutexGuard};
use std::time::{Duration, Instant};

/// Seconds between SIGTERM and SIGKILL (an MPI launcher forwards SIGTERM to its ranks and
/// needs a moment to do so).
pub(crate) const KILL_GRACE_S: f64 = 2.0;

/// Process groups of the programs running now.
static GROUPS: Mutex<Vec<i32>> = Mutex::new(Vec::new());

fn groups() -> MutexGuard<'static, Vec<i32>> {
    GROUPS.lock().unwrap_or_else(|e| e.into_inner())
}

/// A running program's process group; dropped, it kills whatever is left of the group and
/// leaves the registry.
#[derive(Debug)]
pub struct Group {
    pgid: i32,
}

/// Starts `command` as the leader of a new process group, registered until the returned
/// [`Group`] is dropped. The registry is locked across the start, so an interrupt either
/// comes before it (and nothing starts) or sees the new group.
pub fn spawn(command: &mut Command) -> std::io::Result<(Child, Group)> {
    use std::os::unix::process::CommandExt;
    command.process_group(0);
    let mut live = groups();
    let child = command.spawn()?;
    // The leader's pid is the group's id; a pid above i32::MAX does not exist on Linux.
    let pgid = i32::try_from(child.id())
        .map_err(|_| std::io::Error::other(format!("process id {} out of range", child.id())))?;
    live.push(pgid);
    Ok((child, Group { pgid }))
}

impl Group {
    /// The group's id (the leader's pid).
    pub fn id(&self) -> i32 {
        self.pgid
    }

    /// Sends `signal` to every member of the group.
    pub fn signal(&self, signal: i32) {
        signal_group(self.pgid, signal);
    }

    /// SIGTERM to the group, up to [`KILL_GRACE_S`] for the leader to end, then SIGKILL to
    /// the group; always reaps the leader.
    pub(crate) fn terminate(&self, leader: &mut Child) {
        use wait_timeout::ChildExt;
        self.signal(libc::SIGTERM);
        let ended = leader.wait_timeout(Duration::from_secs_f64(KILL_GRACE_S));
        self.signal(libc::SIGKILL);
        if !matches!(ended, Ok(Some(_))) {
            let _ = leader.kill();
            let _ = leader.wait();
        }
    }
}

impl Drop for Group {
    fn drop(&mut self) {
        let mut live = groups();
        // Members the program left behind. The leader is reaped by now, but its pid cannot
        // have been given to a new group leader in between: Linux hands out pids in order and
        // reuses one only after wrapping around the whole range.
        signal_group(self.pgid, libc::SIGKILL);
        live.retain(|&g| g != self.pgid);
    }
}

fn signal_group(pgid: i32, signal: i32) {
    if pgid > 1 {
        // SAFETY: kill(2) on a negative pid signals that process group; no memory is involved.
        unsafe {
            libc::kill(-pgid, signal);
        }
    }
}

/// Whether any process of the group still exists (zombies included).
fn group_exists(pgid: i32) -> bool {
    // SAFETY: signal 0 only checks that the group exists.
    unsafe { libc::kill(-pgid, 0) == 0 }
}

/// For the interrupt handler: SIGTERM to every registered group, up to [`KILL_GRACE_S`] for
/// them to end, then SIGKILL. The returned guard keeps the registry locked, so that no new
/// program starts before the process exits.
pub fn stop_all() -> MutexGuard<'static, Vec<i32>> {
    let live = groups();
    for &g in live.iter() {
        signal_group(g, libc::SIGTERM);
    }
    let deadline = Instant::now() + Duration::from_secs_f64(KILL_GRACE_S);
    while live.iter().any(|&g| group_exists(g)) && Instant::now() < deadline {
        std::thread::sleep(Duration::from_millis(20));
    }
    for &g in live.iter() {
        signal_group(g, libc::SIGKILL);
    }
    live
}

/// The pids of the live (not zombie) processes of group `pgid`, from `/proc`; for tests.
#[doc(hidden)]
pub(crate) fn live_members(pgid: i32) -> Vec<i32> {
    let Ok(entries) = std::fs::read_dir("/proc") else {
        return Vec::new();
    };
    entries
        .flatten()
        .filter_map(|e| e.file_name().to_str()?.parse::<i32>().ok())
        .filter(|&pid| {
            // `pid (comm) state ppid pgrp ...`; comm may hold spaces and parentheses.
            let Ok(stat) = std::fs::read_to_string(format!("/proc/{pid}/stat")) else {
                return false;
            };
            let Some(rest) = stat.rfind(')').map(|i| &stat[i + 1..]) else {
                return false;
            };
            let fields: Vec<&str> = rest.split_whitespace().collect();
            fields.len() > 2 && fields[0] != "Z" && fields[2].parse() == Ok(pgid)
        })
        .collect()
}

/// The live members of group `pgid` still there after up to ten seconds; for tests. A killed
/// process ends when it is next scheduled, so it may outlive the signal by a moment.
#[doc(hidden)]
pub fn members_left(pgid: i32) -> Vec<i32> {
    let deadline = Instant::now() + Duration::from_secs(10);
    loop {
        let members = live_members(pgid);
        if members.is_empty() || Instant::now() >= deadline {
            return members;
        }
        std::thread::sleep(Duration::from_millis(10));
    }
}

/// Whether process `pid` is alive (exists and is not a zombie); for tests.
#[doc(hidden)]
pub fn alive(pid: i32) -> bool {
    std::fs::read_to_string(format!("/proc/{pid}/stat")).is_ok_and(|stat| {
        stat.rfind(')')
            .and_then(|i| stat[i + 1..].split_whitespace().next())
            .is_some_and(|state| state != "Z" && state != "X")
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::process::Stdio;

    fn sh(script: &str) -> Command {
        let mut c = Command::new("sh");
        c.arg("-c")
            .arg(script)
            .stdin(Stdio::null())
            .stdout(Stdio::piped());
        c
    }

    fn first_line(child: &mut Child) -> i32 {
        use std::io::BufRead;
        let out = child.stdout.take().unwrap();
        let mut line = String::new();
        std::io::BufReader::new(out).read_line(&mut line).unwrap();
        line.trim().parse().unwrap()
    }

    #[test]
    fn a_terminated_group_leaves_no_process() {
        let (mut child, group) = spawn(&mut sh("echo $$; sleep 43; echo")).unwrap();
        assert_eq!(
            first_line(&mut child),
            group.id(),
            "the shell leads the group"
        );
        assert!(groups().contains(&group.id()));
        group.terminate(&mut child);
        let pgid = group.id();
        drop(group);
        assert!(!groups().contains(&pgid));
        assert_eq!(members_left(pgid), Vec::<i32>::new(), "sleep 43 survived");
    }

    #[test]
    fn members_left_behind_by_a_finished_program_are_killed() {
        let (mut child, group) = spawn(&mut sh("sleep 43 & echo $!")).unwrap();
        let sleeper = first_line(&mut child);
        assert!(child.wait().unwrap().success());
        assert!(
            alive(sleeper),
            "the background sleep runs until the group is cleared"
        );
        drop(group);
        let deadline = Instant::now() + Duration::from_secs(10);
        while alive(sleeper) && Instant::now() < deadline {
            std::thread::sleep(Duration::from_millis(10));
        }
        assert!(
            !alive(sleeper),
            "the program's background child outlived it"
        );
    }
}
