//! Play / pause / step and the fixed-step accumulator that turns wall-clock time into whole
//! simulation frames, so frame-rate hiccups never change the physics.

/// Longest wall-clock gap credited at once (after a stall the simulation does not race).
const MAX_CREDIT_SECONDS: f64 = 0.25;

#[derive(Clone, Debug, PartialEq)]
pub struct Transport {
    pub playing: bool,
    /// Simulated seconds per wall-clock second.
    pub speed: f32,
    accumulator: f64,
    /// True while the simulation runs slower than `speed` × real time (the stepping thread
    /// owed frames when more became due, or dropped a backlog).
    pub behind: bool,
}

impl Default for Transport {
    fn default() -> Self {
        Self {
            playing: true,
            speed: 1.0,
            accumulator: 0.0,
            behind: false,
        }
    }
}

impl Transport {
    /// Credits `wall_dt` seconds of wall-clock time and returns how many frames of `frame_dt`
    /// seconds are due now.
    pub fn credit(&mut self, wall_dt: f64, frame_dt: f64) -> u32 {
        if !self.playing || frame_dt <= 0.0 {
            self.accumulator = 0.0;
            return 0;
        }
        self.accumulator += wall_dt.clamp(0.0, MAX_CREDIT_SECONDS) * self.speed as f64;
        let due = (self.accumulator / frame_dt).floor();
        self.accumulator -= due * frame_dt;
        due as u32
    }

    /// Pausing also clears the slow-down warning.
    pub fn pause(&mut self) {
        self.playing = false;
        self.behind = false;
        self.accumulator = 0.0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn accumulator_yields_whole_frames_and_keeps_the_remainder() {
        let mut t = Transport::default();
        let dt = 1.0 / 60.0;
        assert_eq!(t.credit(0.01, dt), 0);
        assert_eq!(
            t.credit(0.01, dt),
            1,
            "20 ms of credit holds one 16.7 ms frame"
        );
        assert_eq!(t.credit(0.05, dt), 3);
        t.speed = 0.5;
        assert_eq!(t.credit(1.0 / 30.0, dt), 1);
    }

    #[test]
    fn paused_never_steps_and_a_stall_is_capped() {
        let mut t = Transport::default();
        t.pause();
        assert_eq!(t.credit(1.0, 0.01), 0);
        t.playing = true;
        assert_eq!(
            t.credit(10.0, 0.01),
            25,
            "a 10 s stall credits at most 0.25 s"
        );
    }
}
