//! The loop sets' round: free → generator → ready → frame task → free,
//! and a set that is late.

use core::cell::RefCell;
use core::future::Future;
use core::pin::pin;
use core::task::{Context, Poll, Waker};

use idle_head_core::Timestamp;
use idle_head_core::console::ConsoleLink;
use idle_head_core::idle::{IdleMode, IdlePlayer, LoopStream, LoopSupply};
use idle_head_core::motion::{DEFAULT_HEAD, DEFAULT_N};

use super::{Exchange, FirstSet};
use crate::config::{DEFAULT_TIMING, Set, SetRef};

/// A buffer for the test's life (the boards' are statics).
fn buffer() -> SetRef {
    Box::leak(Box::new(Set::new()))
}

/// Where a buffer is: the same buffer goes round, never a copy.
fn at(set: &Set) -> *const Set {
    set
}

/// Polls `future` once.
fn poll<F: Future>(future: core::pin::Pin<&mut F>) -> Poll<F::Output> {
    future.poll(&mut Context::from_waker(Waker::noop()))
}

/// An exchange with loop set 0 generated into one buffer (handed to the
/// frame task) and the other given to the generator, as the generator
/// task starts it; the stream that follows set 0; the two buffers.
fn started() -> (&'static Exchange, LoopStream<DEFAULT_N>, [*const Set; 2]) {
    let exchange: &'static Exchange = Box::leak(Box::new(Exchange::new()));
    let (first, spare) = (buffer(), buffer());
    let buffers = [at(first), at(spare)];
    first.generate(&DEFAULT_HEAD).unwrap();
    let mut stream = LoopStream::new(DEFAULT_HEAD, &DEFAULT_TIMING);
    stream.adopt(first);
    let info = FirstSet {
        checksum: first.checksum(),
        generated: true,
        precompute: 0,
    };
    exchange.start(first, info);
    exchange.give(spare);
    (exchange, stream, buffers)
}

/// Loop set 0, as the frame task waits for it.
fn first(exchange: &Exchange) -> (SetRef, FirstSet) {
    match poll(pin!(exchange.first())) {
        Poll::Ready(first) => first,
        Poll::Pending => panic!("loop set 0 was not handed over"),
    }
}

#[test]
fn the_sets_go_round_free_generator_ready_frame_task_free() {
    let (exchange, mut stream, [first_buffer, spare_buffer]) = started();
    let link = ConsoleLink::new();
    let (set0, info) = first(exchange);
    assert_eq!(at(set0), first_buffer);
    assert_eq!(info.checksum, set0.checksum());
    let mut supply = exchange.supply();
    assert!(
        supply.take().is_none(),
        "nothing ready before the generator ran"
    );

    let made = RefCell::new(Vec::new());
    let mut generator = pin!(exchange.generate(&mut stream, &link, |result, _| {
        made.borrow_mut().push(result.map(|info| info.number));
    }));
    // The generator takes the free buffer, fills it, hands it over and
    // waits for the next free one.
    assert!(poll(generator.as_mut()).is_pending());
    assert_eq!(*made.borrow(), [Ok(1)]);
    let set1 = supply.take().expect("set 1 ready");
    assert_eq!(at(set1), spare_buffer, "generated in the spare buffer");
    assert_eq!(set1.number(), 1);
    assert!(supply.take().is_none(), "one set per free buffer");
    // Nothing free: the generator waits.
    assert!(poll(generator.as_mut()).is_pending());
    assert_eq!(made.borrow().len(), 1);

    // The frame task gives set 0 back once set 1 has taken over.
    supply.give_back(set0);
    assert!(poll(generator.as_mut()).is_pending());
    assert_eq!(*made.borrow(), [Ok(1), Ok(2)]);
    let set2 = supply.take().expect("set 2 ready");
    assert_eq!(at(set2), first_buffer, "set 0's buffer again");
    assert_eq!(set2.number(), 2);
    supply.give_back(set1);
    assert!(poll(generator.as_mut()).is_pending());
    let set3 = supply.take().expect("set 3 ready");
    assert_eq!((at(set3), set3.number()), (spare_buffer, 3));
}

#[test]
fn the_consoles_seeds_are_taken_for_the_next_set() {
    let seeds = [11, 22, 33];
    // The set after a reseed, made straight from a stream.
    let reference = {
        let (_, mut stream, _) = started();
        stream.reseed(seeds);
        let set = buffer();
        stream.next_into(set).unwrap();
        set.checksum()
    };
    let (exchange, mut stream, _) = started();
    let link = ConsoleLink::new();
    link.reseed(seeds);
    let mut generator = pin!(exchange.generate(&mut stream, &link, |_, _| {}));
    assert!(poll(generator.as_mut()).is_pending());
    let set1 = exchange.supply().take().unwrap();
    assert_eq!(set1.checksum(), reference);
    assert_eq!(link.take_seeds(), None, "the seeds were taken");
}

#[test]
fn a_late_set_plays_the_loop_again_and_joins_a_loop_later() {
    let (exchange, mut stream, _) = started();
    let link = ConsoleLink::new();
    let (set0, _) = first(exchange);
    let mut idle = IdlePlayer::new(
        set0,
        exchange.supply(),
        DEFAULT_TIMING,
        IdleMode::NeverRepeating,
    );
    let frame_us = u64::from(crate::config::DEFAULT_PLAYBACK.frame_period().get());
    let loop_us = DEFAULT_TIMING.loop_us;
    let join_at = DEFAULT_TIMING.period_us();
    let play = |idle: &mut IdlePlayer<_, _>, from: u64, to: u64| -> Vec<_> {
        (from / frame_us..to / frame_us)
            .map(|k| idle.offsets(Timestamp(k * frame_us)))
            .collect()
    };
    // The first loop, and past its join time with no set ready; then on
    // until just before the join a loop later.
    let margin = 10 * frame_us;
    let loop0 = play(&mut idle, 0, join_at + margin);
    let again = play(&mut idle, join_at + margin, loop_us + join_at - margin);
    assert_eq!(idle.stats().late, 1, "the join found no set");
    assert_eq!(idle.stats().set, 0);
    assert_eq!(idle.stats().joins, 0);
    // Played again: a loop later, the same offsets as in the first loop.
    let first_again = loop0.len();
    let per_loop = usize::try_from(loop_us / frame_us).unwrap();
    let replayed = &again[per_loop - first_again..];
    assert!(replayed.len() > 1000);
    assert_eq!(replayed, &loop0[..replayed.len()]);

    // The generator catches up: the next join takes set 1.
    let mut generator = pin!(exchange.generate(&mut stream, &link, |_, _| {}));
    assert!(poll(generator.as_mut()).is_pending());
    let _ = play(
        &mut idle,
        loop_us + join_at - margin,
        loop_us + join_at + margin,
    );
    assert_eq!(idle.stats().joins, 1);
    assert_eq!(idle.stats().set, 1);
    assert_eq!(idle.stats().late, 1);
}
