//! The team: every worker runs the region, barriers order its phases, blocks cover a range,
//! the result is the same at every team size, and a failure or a panic in one worker ends the
//! region on every worker (each test under a time limit: a hang fails it).

use super::*;
use std::sync::atomic::AtomicU64;
use std::sync::mpsc;
use std::time::Duration;

/// Runs `f` on a thread of its own; a test that has not finished after 20 s hangs.
fn within_limit<T: Send + 'static>(f: impl FnOnce() -> T + Send + 'static) -> T {
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(f());
    });
    rx.recv_timeout(Duration::from_secs(20))
        .expect("the team hung (no result within 20 s)")
}

#[test]
fn blocks_cover_the_range_in_order() {
    for size in 1..6 {
        for len in [0, 1, 5, 16, 17, 1000] {
            let blocks: Vec<_> = (0..size).map(|i| block(len, size, i)).collect();
            assert_eq!(blocks[0].start, 0);
            assert_eq!(blocks[size - 1].end, len);
            for w in blocks.windows(2) {
                assert_eq!(w[0].end, w[1].start);
            }
            let lens: Vec<usize> = blocks.iter().map(|b| b.len()).collect();
            assert!(lens.iter().max().unwrap() - lens.iter().min().unwrap() <= 1);
        }
    }
}

/// A two-phase computation: each worker writes its block of squares, and after the barrier
/// reads the whole array (every other worker's block) to sum its own block of neighbours.
fn two_phases(team: &mut Team, n: usize) -> Vec<u64> {
    let squares: Vec<AtomicU64> = (0..n).map(|_| AtomicU64::new(0)).collect();
    let sums: Vec<AtomicU64> = (0..n).map(|_| AtomicU64::new(0)).collect();
    for round in 0..50u64 {
        team.run(|w| {
            for i in w.block(n) {
                squares[i].store((i as u64 + round) * (i as u64 + round), Ordering::Relaxed);
            }
            w.barrier().map_err(|_| "stopped".to_string())?;
            for i in w.block(n) {
                let left = squares[(i + n - 1) % n].load(Ordering::Relaxed);
                let right = squares[(i + 1) % n].load(Ordering::Relaxed);
                sums[i].fetch_add(left + right, Ordering::Relaxed);
            }
            w.barrier().map_err(|_| "stopped".to_string())
        })
        .unwrap();
    }
    sums.iter().map(|s| s.load(Ordering::Relaxed)).collect()
}

#[test]
fn barriers_order_the_phases_and_every_size_gives_the_same_result() {
    within_limit(|| {
        let n = 1001;
        let reference = two_phases(&mut Team::new(1).unwrap(), n);
        for size in [2, 3, 4] {
            let mut team = Team::new(size).unwrap();
            assert_eq!(team.size(), size);
            assert_eq!(two_phases(&mut team, n), reference, "{size} workers");
        }
    });
}

#[test]
fn every_worker_runs_the_region_once() {
    within_limit(|| {
        let mut team = Team::new(3).unwrap();
        for _ in 0..100 {
            let seen: Vec<AtomicUsize> = (0..3).map(|_| AtomicUsize::new(0)).collect();
            team.run(|w| {
                seen[w.index()].fetch_add(1, Ordering::Relaxed);
                Ok(())
            })
            .unwrap();
            assert!(seen.iter().all(|s| s.load(Ordering::Relaxed) == 1));
        }
    });
}

#[test]
fn a_failing_worker_stops_the_others_at_their_barrier() {
    within_limit(|| {
        let mut team = Team::new(3).unwrap();
        let passed = AtomicUsize::new(0);
        let result = team.run(|w| {
            if w.index() == 1 {
                return Err("block 1: particle left the box".into());
            }
            // The others wait for worker 1, which never comes: the barrier must let them go.
            w.barrier().map_err(|_| "stopped".to_string())?;
            passed.fetch_add(1, Ordering::Relaxed);
            Ok(())
        });
        assert_eq!(
            result,
            Err(TeamError::Failed {
                worker: 1,
                message: "block 1: particle left the box".into()
            })
        );
        assert_eq!(passed.load(Ordering::Relaxed), 0);
        // The team works again afterwards.
        team.run(|w| w.barrier().map_err(|_| "stopped".to_string()))
            .unwrap();
    });
}

#[test]
fn a_panicking_worker_ends_the_region_with_its_message() {
    within_limit(|| {
        let mut team = Team::new(2).unwrap();
        for panicking in [0, 1] {
            let result = team.run(|w| {
                if w.index() == panicking {
                    panic!("worker {panicking} out of bounds");
                }
                w.barrier().map_err(|_| "stopped".to_string())?;
                w.barrier().map_err(|_| "stopped".to_string())
            });
            match result {
                Err(TeamError::Panicked { worker, message }) => {
                    assert_eq!(worker, panicking);
                    assert!(message.contains("out of bounds"), "{message}");
                }
                other => panic!("{other:?}"),
            }
        }
    });
}

#[test]
fn a_team_larger_than_the_machine_still_finishes() {
    // More workers than CPUs: waiting workers park instead of spinning forever.
    within_limit(|| {
        let n = 64;
        let reference = two_phases(&mut Team::new(1).unwrap(), n);
        assert_eq!(two_phases(&mut Team::new(8).unwrap(), n), reference);
    });
}
