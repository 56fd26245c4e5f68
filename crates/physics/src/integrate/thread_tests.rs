//! Threads inside one run ([`Settings::threads`]): the plane's step shared by 2 or 3
//! threads gives the run of one thread bit for bit (histories, statistics, impacts,
//! wear, energy), with many contacts closed at once (several chunks of the contact
//! pass), walls that move on their own and a point force, and without them (where the
//! shared step takes the next step's first half with its modal update), for both
//! schemes. Given two threads, the run and its step check run at once and give what
//! they give one after the other.

use std::ops::ControlFlow;

use super::*;
use crate::beam::tests::default_tube;
use crate::contact::{Body, Contact, Law};
use crate::loads::{BaseAcceleration, PointForce, Table};
use crate::modal::ModalBasis;
use crate::stability::Scheme;

/// 37 pins on a hexagonal lattice, 24 levels turning by 60° as a wire-wrapped bundle's
/// do; one contact in three without a gap, the others with small gaps; neighbours
/// released toward each other.
fn bundle(basis: &ModalBasis) -> Model<'_> {
    let rings = 3i64;
    let mut pins = Vec::new();
    for q in -rings..=rings {
        for r in (-rings).max(-q - rings)..=rings.min(-q + rings) {
            pins.push((q, r));
        }
    }
    let index = |at: (i64, i64)| pins.iter().position(|p| *p == at);
    let s3 = 3f64.sqrt() / 2.0;
    let directions = [
        ((1, 0), [1.0, 0.0]),
        ((0, 1), [0.5, s3]),
        ((-1, 1), [-0.5, s3]),
        ((-1, 0), [-1.0, 0.0]),
        ((0, -1), [-0.5, -s3]),
        ((1, -1), [0.5, -s3]),
    ];
    let (mut contacts, mut normals) = (Vec::new(), Vec::new());
    let levels = 24;
    for level in 0..levels {
        let height = 0.1 + 0.85 * level as f64 / levels as f64;
        let ((dq, dr), normal) = directions[level % 6];
        for (p, &(q, r)) in pins.iter().enumerate() {
            let right = index((q + dq, r + dr)).map_or(Body::Wall, Body::Pin);
            let gap = if (p + level) % 3 == 0 {
                0.0
            } else {
                1e-5 * (1.0 + (p % 5) as f64 / 5.0)
            };
            contacts.push(Contact {
                left: Body::Pin(p),
                right,
                height,
                gap,
                stiffness: 1e6,
                damping: 10.0,
                law: Law::LINEAR,
            });
            normals.push(normal);
        }
    }
    let shake = |amplitude: f64, duration: f64| Some(BaseAcceleration::HalfSine { amplitude, duration });
    Model {
        basis,
        pins: pins.len(),
        damping_ratios: vec![0.01; basis.modes()],
        contacts,
        // Along x then along y (one value per line).
        initial_tip_displacements: (0..2 * pins.len())
            .map(|p| if p % 2 == 0 { 2e-4 } else { -1e-4 })
            .collect(),
        initial_tip_velocities: vec![],
        base_acceleration: shake(30.0, 0.004),
        // On pin 5 along x and on pin 8 along y.
        point_forces: [5, pins.len() + 8]
            .map(|line| PointForce {
                line,
                height: 0.7,
                force: Table {
                    time: vec![0.0, 0.002, 0.004],
                    values: vec![0.0, 3.0, 0.0],
                },
            })
            .to_vec(),
        walls: Some(WallMotion::rigid(shake(-20.0, 0.003), shake(10.0, 0.005))),
        plane: Some(Plane {
            normals,
            base_acceleration_y: shake(-20.0, 0.004),
        }),
        kinds: Vec::new(),
    }
}

fn settings(threads: usize) -> Settings {
    Settings {
        scheme: Scheme::CentralDifference,
        time_step: TimeStep::Auto,
        tolerance: DEFAULT_TOLERANCE,
        check: Check::None,
        duration: 0.01,
        output_interval: Some(5e-4),
        output_heights: vec![0.5, 1.0],
        recorded_contacts: None,
        impacts: Default::default(),
        threads,
    }
}

/// The run of `model` with `threads` threads asked, in a pool of `pool` threads.
fn run(model: &Model<'_>, threads: usize, pool: usize) -> Simulation {
    run_with(model, &settings(threads), pool)
}

/// The run of `model` with `settings`, in a pool of `pool` threads.
fn run_with(model: &Model<'_>, settings: &Settings, pool: usize) -> Simulation {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(pool)
        .build()
        .expect("a thread pool");
    pool.install(|| {
        Plan::new(model, settings)
            .expect("a valid model")
            .run(&mut |_| ControlFlow::Continue(()))
            .expect("runs")
            .simulation
    })
}

#[test]
fn results_are_the_same_bit_for_bit_for_every_thread_count() {
    let basis = ModalBasis::compute(&default_tube(20), 6).expect("valid beam");
    let model = bundle(&basis);
    let one = run(&model, 1, 1);
    // The run is worth sharing: more than two chunks of closed contacts at a time on
    // average, and impacts.
    let closed = one.contact_statistics.iter().map(|s| s.contact_time).sum::<f64>() / 0.01;
    assert!(
        closed > 2.0 * plane_step::CLOSED_CHUNK as f64,
        "{closed} contacts closed on average"
    );
    assert!(one.contact_statistics.iter().map(|s| s.impacts).sum::<u64>() > 100);
    assert!(one.energy.relative_residual() < 1e-2, "{:?}", one.energy);
    for (threads, pool) in [(2, 2), (3, 3), (2, 1), (8, 2)] {
        let shared = run(&model, threads, pool);
        assert!(
            shared == one,
            "{threads} threads in a pool of {pool} differ from one thread"
        );
    }
    // Without point forces and moving walls, nothing reads the velocities at the end of
    // a step: the shared step advances the positions of the next one with its update.
    let free = Model {
        point_forces: vec![],
        walls: None,
        ..bundle(&basis)
    };
    for scheme in [Scheme::CentralDifference, Scheme::Tchamwa { phi: 1.1 }] {
        let with = |threads| Settings {
            scheme,
            ..settings(threads)
        };
        let one = run_with(&free, &with(1), 1);
        assert!(one.contact_statistics.iter().map(|s| s.impacts).sum::<u64>() > 100);
        for (threads, pool) in [(2, 2), (3, 3), (2, 1)] {
            assert!(
                run_with(&free, &with(threads), pool) == one,
                "{scheme:?}: {threads} threads in a pool of {pool} differ from one thread"
            );
        }
    }
}

/// The run and its check's verdict with `settings`, in a pool of `pool` threads; the
/// check's wall time (the only thing that may differ) set to zero.
fn assess(model: &Model<'_>, settings: &Settings, pool: usize) -> Assessed {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(pool)
        .build()
        .expect("a thread pool");
    let mut assessed = pool.install(|| {
        Plan::new(model, settings)
            .expect("a valid model")
            .run(&mut |_| ControlFlow::Continue(()))
            .expect("runs")
    });
    if let Some(check) = assessed.quality.step_halving.as_mut() {
        check.seconds = 0.0;
    }
    assessed
}

#[test]
fn a_run_and_its_check_at_once_give_what_they_give_one_after_the_other() {
    let basis = ModalBasis::compute(&default_tube(20), 6).expect("valid beam");
    let model = bundle(&basis);
    for (check, compared_with) in [
        (Check::Auto, quality::StepComparison::DoubleStep),
        (Check::StepHalving, quality::StepComparison::HalfStep),
    ] {
        let settings = |threads| Settings {
            check,
            duration: 0.004,
            ..settings(threads)
        };
        let one = assess(&model, &settings(1), 1);
        let halving = one.quality.step_halving.as_ref().expect("a check ran");
        assert_eq!(halving.compared_with, compared_with, "{check:?}");
        for (threads, pool) in [(2, 2), (3, 3), (2, 1)] {
            let shared = assess(&model, &settings(threads), pool);
            assert!(
                shared == one,
                "{check:?}: {threads} threads in a pool of {pool} differ from one thread"
            );
        }
    }
}

/// Each of two runs given to [`plan::at_once`] waits for the other to start: they can
/// only both finish if they run at the same time.
#[test]
fn two_runs_at_once_run_on_two_threads_of_the_pool() {
    use std::sync::mpsc;
    use std::time::Duration;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .expect("a thread pool");
    let wait = Duration::from_secs(60);
    let (to_there, from_here) = mpsc::channel();
    let (to_here, from_there) = mpsc::channel();
    let (result, reported) = pool.install(move || {
        let mut reported = Vec::new();
        let result = plan::at_once(
            [1.0, 3.0],
            &mut |f| {
                reported.push(f);
                ControlFlow::Continue(())
            },
            |progress| {
                to_there.send(()).expect("the other run listens");
                from_there
                    .recv_timeout(wait)
                    .expect("the other run started while this one ran");
                let _ = progress(1.0);
                Ok("here")
            },
            move |progress| {
                from_here
                    .recv_timeout(wait)
                    .expect("this run started while the other one ran");
                let _ = progress(1.0);
                to_here.send(()).expect("the other run listens");
                Ok("there")
            },
        );
        (result, reported)
    });
    assert_eq!(result, Ok(("here", "there")));
    // Reported from here once, when the other run had reported its end.
    assert_eq!(reported, vec![1.0]);
}

/// A cancellation stops both runs; an error of the other run stops this one and is the
/// error reported.
#[test]
fn runs_at_once_stop_together() {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .expect("a thread pool");
    // Calls `progress` until it says stop (within a minute).
    let until_stopped = |progress: plan::Progress<'_>| -> Result<(), SimulationError> {
        let started = std::time::Instant::now();
        while started.elapsed().as_secs() < 60 {
            if progress(0.5).is_break() {
                return Err(SimulationError::Cancelled);
            }
            std::thread::yield_now();
        }
        panic!("never told to stop");
    };
    let cancelled = pool.install(|| {
        plan::at_once(
            [1.0, 1.0],
            &mut |_| ControlFlow::Break(()),
            until_stopped,
            until_stopped,
        )
    });
    assert_eq!(cancelled, Err(SimulationError::Cancelled));
    let failure = SimulationError::InvalidModel(vec![crate::InputIssue::new("pins", "none")]);
    let failed = pool.install(|| {
        plan::at_once(
            [1.0, 1.0],
            &mut |_| ControlFlow::Continue(()),
            until_stopped,
            |_| Err::<(), _>(failure.clone()),
        )
    });
    assert_eq!(failed, Err(failure));
}

/// The run may change its count of threads from one batch of steps to the next (a
/// worker joins the run's steps once the step check beside it ends): another thread
/// switches the count between one and two every 50 µs while the run steps, at whatever
/// batches that falls on; the results are those of one thread, bit for bit.
#[test]
fn the_step_gives_the_same_numbers_when_its_threads_change_between_batches() {
    use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
    let basis = ModalBasis::compute(&default_tube(20), 6).expect("valid beam");
    let with_loads = bundle(&basis);
    let free = Model {
        point_forces: vec![],
        walls: None,
        ..bundle(&basis)
    };
    for model in [&with_loads, &free] {
        let one = run(model, 1, 1);
        let settings = settings(2);
        let plan = Plan::new(model, &settings).expect("a valid model");
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .expect("a thread pool");
        let (helping, done) = (AtomicUsize::new(0), AtomicBool::new(false));
        let mut switches = 0u64;
        let switched = std::thread::scope(|scope| {
            scope.spawn(|| {
                while !done.load(Ordering::Acquire) {
                    helping.store(1 - helping.load(Ordering::Acquire), Ordering::Release);
                    switches += 1;
                    std::thread::sleep(std::time::Duration::from_micros(50));
                }
            });
            let simulation = pool.install(|| {
                stepper::time_loop(
                    pulp::Arch::new(),
                    model,
                    &settings,
                    plan.step(),
                    (2, Some(&helping)),
                    &mut |_| ControlFlow::Continue(()),
                )
            });
            done.store(true, Ordering::Release);
            simulation.expect("runs")
        });
        assert!(switches > 10, "{switches} switches");
        assert!(
            switched == one,
            "the run whose threads changed differs from one thread"
        );
    }
}
