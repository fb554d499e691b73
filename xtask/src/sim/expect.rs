//! What the Pico image must write, computed on the host by the same core.

use anyhow::{Result, anyhow, bail};
use embedded_hal::pwm::{ErrorType, SetDutyCycle};
use idle_head_core::driver::{DriverConfig, FrameDriver};
use idle_head_core::motion::DEFAULT_N;
use idle_head_firmware::config::LOOP_DURATION;
use idle_head_firmware::frame::FrameLoop;

use idle_head_core::Playback;
use idle_head_core::pwm_clock::PICO_SERVO_CLOCK;

/// embassy-time's tick rate on the RP2040 (its 1 MHz TIMER).
const TICK_HZ: u64 = 1_000_000;

/// The duties `[pitch, roll, yaw]` of frames `0..frames` of the Pico image,
/// every frame on time: its `FrameLoop` and `FrameDriver` on the defaults.
pub fn pico_duties(frames: usize) -> Result<Vec<[u16; 3]>> {
    let config = DriverConfig::DEFAULT;
    let params = config.build().map_err(|e| anyhow!("{}", e.message()))?;
    let playback = Playback::new(LOOP_DURATION, config.frame_period, DEFAULT_N)
        .map_err(|e| anyhow!("playback: {e:?}"))?;
    let idle = crate::trace::idle(playback, None)?;
    let mut frame_loop = FrameLoop::new(idle, config.frame_period, TICK_HZ, 0)
        .map_err(|e| anyhow!("frame loop: {e:?}"))?;
    let mut driver = FrameDriver::new([(); 3].map(|()| Recorder::default()), params);
    for _ in 0..frames {
        let tick = frame_loop.next(frame_loop.deadline());
        frame_loop.write(&mut driver, tick);
    }
    let [p, r, y] = driver.release().map(|recorder| recorder.0);
    if [&p, &r, &y].iter().any(|duties| duties.len() != frames) {
        bail!("the host driver did not write every servo once per frame");
    }
    Ok((0..frames).map(|k| [p[k], r[k], y[k]]).collect())
}

/// A PWM channel with the Pico's `TOP` that keeps every duty written.
#[derive(Default)]
struct Recorder(Vec<u16>);

impl ErrorType for Recorder {
    type Error = core::convert::Infallible;
}

impl SetDutyCycle for Recorder {
    fn max_duty_cycle(&self) -> u16 {
        PICO_SERVO_CLOCK.top
    }

    fn set_duty_cycle(&mut self, duty: u16) -> Result<(), Self::Error> {
        self.0.push(duty);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn neutral_first_then_the_fade_moves_the_servos() {
        let duties = pico_duties(200).unwrap();
        // 1500 µs of 20 000 µs at TOP = 63 999: 4799.9 counts.
        assert_eq!(duties[0], [4800; 3]);
        assert!(duties[150].iter().any(|&d| d != 4800));
    }
}
