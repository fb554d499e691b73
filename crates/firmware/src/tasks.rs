//! The bodies of the tasks every board runs: the loop generator's,
//! [`generate`], and the frame task's, [`play`]. Each board calls them from
//! one-line embassy tasks of its own: the frame task's types are the
//! board's (embassy tasks cannot be generic), and an embassy task defined
//! here would be linked into every image of a board, the frame path's
//! panic proof included, whether it is spawned or not.

use embassy_time::Duration;
use idle_head_core::behaviour::BehaviourParams;
use idle_head_core::driver::FrameDriver;
use idle_head_core::idle::{IdleMode, IdleStats, LoopStream, SetInfo};
use idle_head_core::motion::AxisError;
use idle_head_core::playback::Playback;
use idle_head_core::servo::SetPeriod;

use crate::boot::{Generator, Links, Stopwatch, first_set};
use crate::config::{DEFAULT_TIMING, IDLE_MODE, SetRef};
use crate::frame::{FrameHooks, FrameLoop, RunStats};
use crate::log;

/// The generator task's body: generates loop set 0 (timed by `stopwatch`)
/// and hands it to the frame task, then each next set while the frames
/// play (thread mode, below the frame task), logging each.
pub async fn generate(generator: Generator, mut stopwatch: impl Stopwatch) -> ! {
    let Generator {
        head,
        first,
        spare,
        links,
    } = generator;
    let exchange = &links.exchange;
    let info = first_set(first, &head, &mut stopwatch);
    match IDLE_MODE {
        IdleMode::NeverRepeating => {
            // The stream starts from the boot set, whose pace it measures
            // (a fixed loop has no stream and skips that).
            let mut stream = LoopStream::new(head, &DEFAULT_TIMING);
            stream.adopt(first);
            log::info!(
                "idle: never repeating, a new loop set every {=u64} ms, joined over {=u64} ms",
                DEFAULT_TIMING.period_us() / 1000,
                DEFAULT_TIMING.join_us / 1000
            );
            exchange.start(first, info);
            exchange.give(spare);
            exchange
                .generate(&mut stream, &links.console, log_set)
                .await
        }
        IdleMode::FixedLoop => {
            log::info!("idle: the fixed loop, replayed every loop");
            exchange.start(first, info);
            core::future::pending().await
        }
    }
}

/// Logs a loop set the generator made.
fn log_set(result: &Result<SetInfo, AxisError>, ticks: u64) {
    match result {
        Ok(info) => log::info!(
            "loop set {=u32} ready in {=u64} us: seeds {:#010x} ({} discarded), entered at {}, join mismatch {} mdeg rms",
            info.number,
            Duration::from_ticks(ticks).as_micros(),
            info.seeds,
            info.discarded,
            info.starts,
            info.mismatch
        ),
        Err(e) => log::error!(
            "loop set failed: {=str} {=str}; trying the next seeds",
            e.axis.name(),
            e.error.message()
        ),
    }
}

/// The playback the frame task runs at: the default loops at 20 ms frames,
/// or with the `calibrate` feature the calibration sweep's.
#[must_use]
pub const fn playback() -> Playback {
    #[cfg(feature = "calibrate")]
    {
        crate::calibrate::playback(idle_head_core::driver::DriverConfig::DEFAULT.frame_period)
    }
    #[cfg(not(feature = "calibrate"))]
    {
        crate::config::DEFAULT_PLAYBACK
    }
}

/// The frame task's body: plays the idle from loop set `first` (from
/// [`Exchange::first`](crate::exchange::Exchange::first); and the
/// generator's sets after it), with `behaviour` and the console's commands,
/// through `driver`, each frame on the timer of `tick_hz` ticks a second,
/// until `hooks` says stop (the frames of a board never stop but in the
/// watchdog drill). `frame_period` is the board's time between frames at
/// the driver's rate (the QEMU smoke run plays faster than real time): the
/// outputs and the idle start at the driver's period, the settings' rate.
/// The commands, the console's link, the show's inputs and the loop sets
/// come through `links`. Returns the frames' and the idle's totals.
pub async fn play<P: SetPeriod, H: FrameHooks<P>>(
    driver: &mut FrameDriver<P>,
    first: SetRef,
    behaviour: &BehaviourParams,
    hooks: &mut H,
    frame_period: idle_head_core::Microseconds,
    links: &'static Links,
) -> (RunStats, IdleStats) {
    let period = driver.params().config().frame_period;
    if let Err(e) = driver.set_pwm_period(period) {
        log::error!("servo outputs refused {=u32} us: {}", period.0, e);
    }
    let start = embassy_time::Instant::now().as_ticks();
    #[cfg(not(feature = "calibrate"))]
    let mut idle = idle_head_core::idle::IdlePlayer::new(
        first,
        links.exchange.supply(),
        DEFAULT_TIMING,
        IDLE_MODE,
    );
    #[cfg(feature = "calibrate")]
    let mut idle = {
        let _ = first;
        crate::calibrate::player()
    };
    idle.set_frame_period(period);
    let frames =
        FrameLoop::with_behaviour(idle, frame_period, *behaviour, embassy_time::TICK_HZ, start);
    let Ok(frames) = frames else {
        log::error!("frame period below one timer tick");
        return (RunStats::default(), IdleStats::default());
    };
    let mut frames = frames
        .with_latch_divisor(P::LATCH_DIVISOR)
        .with_commands(&links.commands)
        .with_link(&links.console)
        .with_show(&links.show);
    let run = crate::frame::run(driver, &mut frames, hooks, &links.latest_wake_us).await;
    #[cfg(not(feature = "calibrate"))]
    let idle = frames.idle_mut().stats();
    #[cfg(feature = "calibrate")]
    let idle = IdleStats::default();
    (run, idle)
}
