//! The working memory and the 33 rules of `rules/outdoor.situ`, by hand.
//!
//! Semantics: `docs/language.md` §10.1–10.4 and `bench/README.md`. Each agent
//! has at most one fact, its latest event; a rule is a plain Rust test on the
//! facts of the agents it names. `Engine::select` finds the activated rule to
//! fire with a `match` on the current state that offers only the rules whose
//! state test admits that state.

use crate::model::{Agent, Ev, Event, State, Value, AGENTS, STALE_AFTER, WITHIN_100MS, WITHIN_500MS};

/// At most this many firings per rest (§10.4); one more is a runtime error.
pub const MAX_FIRINGS: usize = 64;

/// An agent's slot in the working memory.
#[derive(Clone, Copy, Debug)]
struct Fact {
    /// The latest event; `None` when the agent never reported (since the last
    /// reset) or when its fact expired.
    ev: Option<Ev>,
    /// The fact expired (`stale A` holds) and the agent has not reported since.
    stale: bool,
    /// How many times in a row the agent reported this event.
    run: u32,
    /// Timestamp (ns).
    t: u64,
    /// Posting order, for recency: larger is newer; 0 is never used by a fact.
    seq: u64,
    p: [Value; 2],
}

const NO_FACT: Fact = Fact { ev: None, stale: false, run: 0, t: 0, seq: 0, p: [Value::None; 2] };

impl Fact {
    #[inline(always)]
    fn f64(&self, field: usize) -> f64 {
        self.p[field].f64()
    }
}

/// The rules of `outdoor.situ`, in declaration order (the last tie-breaker).
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
#[repr(u8)]
pub enum Rule {
    PlannerFailed,
    DriveFault,
    CollisionImminent,
    LocalizationLost,
    LocalizationSilent,
    LadarSilent,
    RoadCameraSilent,
    StereoSilent,
    SafetyRadioLost,
    OperatorTakesOver,
    SupervisorStop,
    EmergencyHalted,
    GoalReached,
    ReadinessLost,
    RoadObstacleLadar,
    RoadObstacleStereo,
    TerrainObstacleLadar,
    TerrainObstacleStereo,
    ObstaclePassedStraight,
    ObstaclePassedInTurn,
    ObstaclePassedAtBranch,
    RoadObstacleOffRoad,
    TerrainObstaclePassed,
    TerrainObstacleOntoRoad,
    Initialized,
    StartOnRoad,
    StartInTurn,
    StartCrossCountry,
    RoadStraight,
    RoadTurn,
    RoadBranch,
    RoadEnds,
    BackOnRoad,
}

impl Rule {
    /// Every rule, in declaration order.
    #[cfg(test)]
    pub const ALL: [Rule; 33] = {
        use Rule::*;
        [
            PlannerFailed,
            DriveFault,
            CollisionImminent,
            LocalizationLost,
            LocalizationSilent,
            LadarSilent,
            RoadCameraSilent,
            StereoSilent,
            SafetyRadioLost,
            OperatorTakesOver,
            SupervisorStop,
            EmergencyHalted,
            GoalReached,
            ReadinessLost,
            RoadObstacleLadar,
            RoadObstacleStereo,
            TerrainObstacleLadar,
            TerrainObstacleStereo,
            ObstaclePassedStraight,
            ObstaclePassedInTurn,
            ObstaclePassedAtBranch,
            RoadObstacleOffRoad,
            TerrainObstaclePassed,
            TerrainObstacleOntoRoad,
            Initialized,
            StartOnRoad,
            StartInTurn,
            StartCrossCountry,
            RoadStraight,
            RoadTurn,
            RoadBranch,
            RoadEnds,
            BackOnRoad,
        ]
    };

    /// (salience, specificity, target). Specificity counts, as §10.4 says, each
    /// state test, `stale` test, pattern (also under `not`), payload constraint,
    /// run length `xN` with N >= 2 and `within`.
    #[inline(always)]
    pub const fn meta(self) -> (i32, u32, State) {
        use Rule::*;
        use State::*;
        match self {
            PlannerFailed => (100, 2, EM),
            DriveFault => (100, 2, EM),
            CollisionImminent => (100, 4, EM),
            LocalizationLost => (100, 2, EM),
            LocalizationSilent => (100, 2, EM),
            LadarSilent => (100, 2, EM),
            RoadCameraSilent => (100, 2, EM),
            StereoSilent => (100, 2, EM),
            SafetyRadioLost => (100, 2, EM),
            OperatorTakesOver => (90, 2, SP),
            SupervisorStop => (90, 2, SP),
            EmergencyHalted => (90, 2, SP),
            GoalReached => (80, 3, GL),
            ReadinessLost => (60, 2, IT),
            RoadObstacleLadar => (50, 4, RO),
            RoadObstacleStereo => (50, 3, RO),
            TerrainObstacleLadar => (50, 4, CO),
            TerrainObstacleStereo => (50, 3, CO),
            ObstaclePassedStraight => (40, 9, RS),
            ObstaclePassedInTurn => (40, 9, RT),
            ObstaclePassedAtBranch => (40, 9, RB),
            RoadObstacleOffRoad => (40, 5, CO),
            TerrainObstaclePassed => (40, 8, CN),
            TerrainObstacleOntoRoad => (40, 5, RO),
            Initialized => (30, 6, RD),
            StartOnRoad => (30, 7, RS),
            StartInTurn => (30, 7, RT),
            StartCrossCountry => (30, 6, CN),
            RoadStraight => (30, 3, RS),
            RoadTurn => (30, 4, RT),
            RoadBranch => (30, 3, RB),
            RoadEnds => (30, 4, CN),
            BackOnRoad => (30, 4, RS),
        }
    }

    #[inline(always)]
    pub const fn target(self) -> State {
        self.meta().2
    }

    /// The rule's state test, as written in outdoor.situ (used by the tests to
    /// check that `Engine::select` offers each rule in exactly these states).
    #[cfg(test)]
    pub fn admits(self, s: State) -> bool {
        use Rule::*;
        use State::*;
        let moving = matches!(s, RS | RT | RB | RO | CN | CO);
        match self {
            PlannerFailed | DriveFault => !matches!(s, EM | GL | SP),
            CollisionImminent | LocalizationLost | LocalizationSilent | LadarSilent | SafetyRadioLost => moving,
            RoadCameraSilent => matches!(s, RS | RT | RB | RO),
            StereoSilent => matches!(s, CN | CO),
            OperatorTakesOver | SupervisorStop => !matches!(s, GL | SP),
            EmergencyHalted => s == EM,
            GoalReached => moving,
            ReadinessLost => s == RD,
            RoadObstacleLadar | RoadObstacleStereo => matches!(s, RS | RT | RB),
            TerrainObstacleLadar | TerrainObstacleStereo => s == CN,
            ObstaclePassedStraight | ObstaclePassedInTurn | ObstaclePassedAtBranch | RoadObstacleOffRoad => s == RO,
            TerrainObstaclePassed | TerrainObstacleOntoRoad => s == CO,
            Initialized => s == IT,
            StartOnRoad | StartInTurn | StartCrossCountry => s == RD,
            RoadStraight => matches!(s, RT | RB),
            RoadTurn => matches!(s, RS | RB),
            RoadBranch => matches!(s, RS | RT),
            RoadEnds => matches!(s, RS | RT | RB),
            BackOnRoad => s == CN,
        }
    }

    /// The rule's name in outdoor.situ.
    pub fn name(self) -> &'static str {
        use Rule::*;
        match self {
            PlannerFailed => "planner_failed",
            DriveFault => "drive_fault",
            CollisionImminent => "collision_imminent",
            LocalizationLost => "localization_lost",
            LocalizationSilent => "localization_silent",
            LadarSilent => "ladar_silent",
            RoadCameraSilent => "road_camera_silent",
            StereoSilent => "stereo_silent",
            SafetyRadioLost => "safety_radio_lost",
            OperatorTakesOver => "operator_takes_over",
            SupervisorStop => "supervisor_stop",
            EmergencyHalted => "emergency_halted",
            GoalReached => "goal_reached",
            ReadinessLost => "readiness_lost",
            RoadObstacleLadar => "road_obstacle_ladar",
            RoadObstacleStereo => "road_obstacle_stereo",
            TerrainObstacleLadar => "terrain_obstacle_ladar",
            TerrainObstacleStereo => "terrain_obstacle_stereo",
            ObstaclePassedStraight => "obstacle_passed_straight",
            ObstaclePassedInTurn => "obstacle_passed_in_turn",
            ObstaclePassedAtBranch => "obstacle_passed_at_branch",
            RoadObstacleOffRoad => "road_obstacle_off_road",
            TerrainObstaclePassed => "terrain_obstacle_passed",
            TerrainObstacleOntoRoad => "terrain_obstacle_onto_road",
            Initialized => "initialized",
            StartOnRoad => "start_on_road",
            StartInTurn => "start_in_turn",
            StartCrossCountry => "start_cross_country",
            RoadStraight => "road_straight",
            RoadTurn => "road_turn",
            RoadBranch => "road_branch",
            RoadEnds => "road_ends",
            BackOnRoad => "back_on_road",
        }
    }
}

/// A rest needed more than [`MAX_FIRINGS`] firings: the rules that fired.
#[derive(Debug)]
pub struct CascadeError {
    pub fired: Vec<Rule>,
}

/// The best activated rule seen so far while `select` offers candidates.
struct Pick {
    best: Option<Rule>,
    /// The best rule's recency: the `seq` of its newest matched positive fact
    /// (0 when it matches no fact).
    recency: u64,
}

/// The Bulletinboard of outdoor.situ, by hand.
pub struct Engine {
    state: State,
    /// The largest timestamp posted so far.
    now: u64,
    facts: [Fact; AGENTS],
    /// Facts posted so far: the next fact's `seq` is `seq + 1`.
    seq: u64,
    /// The state was set without firing rules (tests' `given`): the next event
    /// brings the network to rest before inserting its fact even if nothing
    /// expires.
    unsettled: bool,
    /// The rules fired while processing the latest event, in order.
    fired: [Rule; 2 * MAX_FIRINGS],
    fired_len: usize,
    /// Rules offered by `select` (a bit per rule), to check its `match`.
    #[cfg(test)]
    offered: std::cell::Cell<u64>,
}

impl Default for Engine {
    fn default() -> Self {
        Self::new()
    }
}

impl Engine {
    /// The initial state with no facts, now = 0.
    pub fn new() -> Self {
        Engine {
            state: State::INITIAL,
            now: 0,
            facts: [NO_FACT; AGENTS],
            seq: 0,
            unsettled: false,
            fired: [Rule::PlannerFailed; 2 * MAX_FIRINGS],
            fired_len: 0,
            #[cfg(test)]
            offered: std::cell::Cell::new(0),
        }
    }

    /// The current state (after `post`, the state at rest).
    #[cfg(test)]
    pub fn state(&self) -> State {
        self.state
    }

    /// The rules fired while processing the latest event.
    pub fn fired(&self) -> &[Rule] {
        &self.fired[..self.fired_len]
    }

    /// Posts one event and brings the network to rest; returns the state at
    /// rest. If the state at rest after the previous event was final, the
    /// mission was over: the engine is first reset to the initial state with
    /// no facts (now is kept).
    #[inline]
    pub fn post(&mut self, e: &Event) -> Result<State, CascadeError> {
        if self.state.is_final() {
            self.reset();
        }
        self.fired_len = 0;
        if e.t > self.now {
            self.now = e.t;
        }
        // Expiry, then rest. When nothing expired (and the previous event left
        // the network at rest), the rest would fire nothing: the working memory
        // is unchanged but for `now`, and a later `now` can only make `within`
        // patterns fail, which can enable no rule of outdoor.situ (none has a
        // `within` under `not`).
        if self.expire() || self.unsettled {
            self.unsettled = false;
            self.rest()?;
        }
        self.insert(e);
        self.rest()?;
        Ok(self.state)
    }

    /// Back to the initial state with no facts; now is kept.
    fn reset(&mut self) {
        self.state = State::INITIAL;
        self.facts = [NO_FACT; AGENTS];
    }

    /// Expires every fact older than its agent's `stale after` (`now - t > D`).
    /// Returns whether any fact expired.
    #[inline(always)]
    fn expire(&mut self) -> bool {
        let mut any = false;
        for (agent, d) in STALE_AFTER {
            let f = &mut self.facts[agent as usize];
            if f.ev.is_some() && self.now - f.t > d {
                f.ev = None;
                f.stale = true;
                any = true;
            }
        }
        any
    }

    /// Replaces the agent's fact with the event.
    #[inline(always)]
    fn insert(&mut self, e: &Event) {
        self.seq += 1;
        let f = &mut self.facts[e.agent as usize];
        // An expired fact has `ev == None`, so the run restarts at 1.
        f.run = if f.ev == Some(e.ev) { f.run.saturating_add(1) } else { 1 };
        f.ev = Some(e.ev);
        f.stale = false;
        f.t = e.t;
        f.seq = self.seq;
        f.p = e.p;
    }

    /// Fires the best activated rule until none is activated.
    #[inline(always)]
    fn rest(&mut self) -> Result<(), CascadeError> {
        let mut firings = 0;
        while let Some(rule) = self.select() {
            if firings == MAX_FIRINGS {
                let mut fired = self.fired().to_vec();
                fired.push(rule);
                return Err(CascadeError { fired });
            }
            firings += 1;
            self.fired[self.fired_len] = rule;
            self.fired_len += 1;
            self.state = rule.target();
        }
        Ok(())
    }

    // ─── Conflict resolution ───────────────────────────────────────────────

    /// Offers `rule` if its target differs from the current state and `cond`
    /// (the rule's conditions but its state test) holds, returning its recency.
    /// Keeps the best by salience, specificity, recency, then declaration order.
    /// `cond` is not evaluated when the rule cannot beat the best one.
    #[inline(always)]
    fn offer(&self, pick: &mut Pick, rule: Rule, cond: impl FnOnce(&Self) -> Option<u64>) {
        #[cfg(test)]
        self.offered.set(self.offered.get() | 1 << rule as u32);
        let (salience, specificity, target) = rule.meta();
        if target == self.state {
            return;
        }
        if let Some(best) = pick.best {
            let (bs, bp, _) = best.meta();
            if (salience, specificity) < (bs, bp) {
                return;
            }
        }
        let Some(recency) = cond(self) else { return };
        let better = match pick.best {
            None => true,
            Some(best) => {
                let (bs, bp, _) = best.meta();
                (salience, specificity, recency) > (bs, bp, pick.recency)
                    || ((salience, specificity, recency) == (bs, bp, pick.recency) && (rule as u8) < (best as u8))
            }
        };
        if better {
            pick.best = Some(rule);
            pick.recency = recency;
        }
    }

    /// The activated rule to fire in the current working memory, if any.
    #[inline(always)]
    fn select(&self) -> Option<Rule> {
        use Rule::*;
        let mut p = Pick { best: None, recency: 0 };
        let p = &mut p;
        match self.state {
            State::IT => {
                self.offer(p, PlannerFailed, Self::planner_failed);
                self.offer(p, DriveFault, Self::drive_fault);
                self.offer(p, OperatorTakesOver, Self::operator_takes_over);
                self.offer(p, SupervisorStop, Self::supervisor_stop);
                self.offer(p, Initialized, Self::initialized);
            }
            State::RD => {
                self.offer(p, PlannerFailed, Self::planner_failed);
                self.offer(p, DriveFault, Self::drive_fault);
                self.offer(p, OperatorTakesOver, Self::operator_takes_over);
                self.offer(p, SupervisorStop, Self::supervisor_stop);
                self.offer(p, ReadinessLost, Self::readiness_lost);
                self.offer(p, StartOnRoad, Self::start_on_road);
                self.offer(p, StartInTurn, Self::start_in_turn);
                self.offer(p, StartCrossCountry, Self::start_cross_country);
            }
            State::RS | State::RT | State::RB => {
                self.offer_moving(p);
                self.offer(p, RoadCameraSilent, Self::road_camera_silent);
                self.offer(p, RoadObstacleLadar, Self::road_obstacle_ladar);
                self.offer(p, RoadObstacleStereo, Self::road_obstacle_stereo);
                // Each road-geometry rule names the states it leaves; `offer`
                // also skips the one whose target is the current state.
                if self.state != State::RS {
                    self.offer(p, RoadStraight, Self::road_straight);
                }
                if self.state != State::RT {
                    self.offer(p, RoadTurn, Self::road_turn);
                }
                if self.state != State::RB {
                    self.offer(p, RoadBranch, Self::road_branch);
                }
                self.offer(p, RoadEnds, Self::road_ends);
            }
            State::RO => {
                self.offer_moving(p);
                self.offer(p, RoadCameraSilent, Self::road_camera_silent);
                self.offer(p, ObstaclePassedStraight, Self::obstacle_passed_straight);
                self.offer(p, ObstaclePassedInTurn, Self::obstacle_passed_in_turn);
                self.offer(p, ObstaclePassedAtBranch, Self::obstacle_passed_at_branch);
                self.offer(p, RoadObstacleOffRoad, Self::road_obstacle_off_road);
            }
            State::CN => {
                self.offer_moving(p);
                self.offer(p, StereoSilent, Self::stereo_silent);
                self.offer(p, TerrainObstacleLadar, Self::terrain_obstacle_ladar);
                self.offer(p, TerrainObstacleStereo, Self::terrain_obstacle_stereo);
                self.offer(p, BackOnRoad, Self::back_on_road);
            }
            State::CO => {
                self.offer_moving(p);
                self.offer(p, StereoSilent, Self::stereo_silent);
                self.offer(p, TerrainObstaclePassed, Self::terrain_obstacle_passed);
                self.offer(p, TerrainObstacleOntoRoad, Self::terrain_obstacle_onto_road);
            }
            State::EM => {
                self.offer(p, OperatorTakesOver, Self::operator_takes_over);
                self.offer(p, SupervisorStop, Self::supervisor_stop);
                self.offer(p, EmergencyHalted, Self::emergency_halted);
            }
            // Final: no rule of outdoor.situ admits GL or SP.
            State::GL | State::SP => {}
        }
        p.best
    }

    /// The rules that hold in every moving state (RS RT RB RO CN CO).
    #[inline(always)]
    fn offer_moving(&self, p: &mut Pick) {
        use Rule::*;
        self.offer(p, PlannerFailed, Self::planner_failed);
        self.offer(p, DriveFault, Self::drive_fault);
        self.offer(p, CollisionImminent, Self::collision_imminent);
        self.offer(p, LocalizationLost, Self::localization_lost);
        self.offer(p, LocalizationSilent, Self::localization_silent);
        self.offer(p, LadarSilent, Self::ladar_silent);
        self.offer(p, SafetyRadioLost, Self::safety_radio_lost);
        self.offer(p, OperatorTakesOver, Self::operator_takes_over);
        self.offer(p, SupervisorStop, Self::supervisor_stop);
        self.offer(p, GoalReached, Self::goal_reached);
    }

    // ─── Patterns ──────────────────────────────────────────────────────────

    /// The live fact of `ev`'s agent if its event is `ev` (condition 1 of §10.3).
    #[inline(always)]
    fn fact(&self, ev: Ev) -> Option<&Fact> {
        let f = &self.facts[ev.agent() as usize];
        if f.ev == Some(ev) {
            Some(f)
        } else {
            None
        }
    }

    /// `E`: the matched fact's seq.
    #[inline(always)]
    fn is(&self, ev: Ev) -> Option<u64> {
        self.fact(ev).map(|f| f.seq)
    }

    /// `E xN`.
    #[inline(always)]
    fn run(&self, ev: Ev, n: u32) -> Option<u64> {
        self.fact(ev).filter(|f| f.run >= n).map(|f| f.seq)
    }

    /// `E within 500ms`.
    #[inline(always)]
    fn within_500ms(&self, ev: Ev) -> Option<u64> {
        self.fact(ev).filter(|f| self.now - f.t <= WITHIN_500MS).map(|f| f.seq)
    }

    /// `E within 100ms`.
    #[inline(always)]
    fn within_100ms(&self, ev: Ev) -> Option<u64> {
        self.fact(ev).filter(|f| self.now - f.t <= WITHIN_100MS).map(|f| f.seq)
    }

    /// `stale A`: a rule condition that matches no fact (recency 0).
    #[inline(always)]
    fn stale(&self, agent: Agent) -> Option<u64> {
        self.facts[agent as usize].stale.then_some(0)
    }

    /// `STOBS(distance < 30.0)`, used positively and under `not`.
    #[inline(always)]
    fn stobs_within_30m(&self) -> Option<u64> {
        self.fact(Ev::STOBS).filter(|f| f.f64(0) < 30.0).map(|f| f.seq)
    }

    // ─── The rules (their state tests are in `select`) ─────────────────────

    // 100: emergency

    /// planner_failed: state not in {EM, GL, SP} and PLF → EM
    fn planner_failed(&self) -> Option<u64> {
        self.is(Ev::PLF)
    }

    /// drive_fault: state not in {EM, GL, SP} and DRFAULT → EM
    fn drive_fault(&self) -> Option<u64> {
        self.is(Ev::DRFAULT)
    }

    /// collision_imminent: state in {RS, RT, RB, RO, CN, CO} and LAOBS(distance < 5.0, height > 0.15) → EM
    fn collision_imminent(&self) -> Option<u64> {
        self.fact(Ev::LAOBS).filter(|f| f.f64(0) < 5.0 && f.f64(1) > 0.15).map(|f| f.seq)
    }

    /// localization_lost: state in {RS, RT, RB, RO, CN, CO} and LOLOST → EM
    fn localization_lost(&self) -> Option<u64> {
        self.is(Ev::LOLOST)
    }

    /// localization_silent: state in {RS, RT, RB, RO, CN, CO} and stale Localization → EM
    fn localization_silent(&self) -> Option<u64> {
        self.stale(Agent::Localization)
    }

    /// ladar_silent: state in {RS, RT, RB, RO, CN, CO} and stale LADAR → EM
    fn ladar_silent(&self) -> Option<u64> {
        self.stale(Agent::LADAR)
    }

    /// road_camera_silent: state in {RS, RT, RB, RO} and stale RFCCD → EM
    fn road_camera_silent(&self) -> Option<u64> {
        self.stale(Agent::RFCCD)
    }

    /// stereo_silent: state in {CN, CO} and stale STCCD → EM
    fn stereo_silent(&self) -> Option<u64> {
        self.stale(Agent::STCCD)
    }

    /// safety_radio_lost: state in {RS, RT, RB, RO, CN, CO} and stale TeleControl → EM
    fn safety_radio_lost(&self) -> Option<u64> {
        self.stale(Agent::TeleControl)
    }

    // 90: stop

    /// operator_takes_over: state not in {GL, SP} and TCTAKE → SP
    fn operator_takes_over(&self) -> Option<u64> {
        self.is(Ev::TCTAKE)
    }

    /// supervisor_stop: state not in {GL, SP} and SVSTOP → SP
    fn supervisor_stop(&self) -> Option<u64> {
        self.is(Ev::SVSTOP)
    }

    /// emergency_halted: state == EM and DRSTOP within 100ms → SP
    fn emergency_halted(&self) -> Option<u64> {
        self.within_100ms(Ev::DRSTOP)
    }

    // 80: goal

    /// goal_reached: state in {RS, RT, RB, RO, CN, CO} and GPGL(remaining < 2.0) → GL
    fn goal_reached(&self) -> Option<u64> {
        self.fact(Ev::GPGL).filter(|f| f.f64(0) < 2.0).map(|f| f.seq)
    }

    // 60: readiness lost

    /// readiness_lost: state == RD and LOLOST → IT
    fn readiness_lost(&self) -> Option<u64> {
        self.is(Ev::LOLOST)
    }

    // 50: an obstacle is seen

    /// road_obstacle_ladar: state in {RS, RT, RB} and LAOBS(distance < 30.0, height > 0.15) → RO
    fn road_obstacle_ladar(&self) -> Option<u64> {
        self.fact(Ev::LAOBS).filter(|f| f.f64(0) < 30.0 && f.f64(1) > 0.15).map(|f| f.seq)
    }

    /// road_obstacle_stereo: state in {RS, RT, RB} and STOBS(distance < 30.0) → RO
    fn road_obstacle_stereo(&self) -> Option<u64> {
        self.stobs_within_30m()
    }

    /// terrain_obstacle_ladar: state == CN and LAOBS(distance < 20.0, height > 0.3) → CO
    fn terrain_obstacle_ladar(&self) -> Option<u64> {
        self.fact(Ev::LAOBS).filter(|f| f.f64(0) < 20.0 && f.f64(1) > 0.3).map(|f| f.seq)
    }

    /// terrain_obstacle_stereo: state == CN and STOBS(distance < 20.0) → CO
    fn terrain_obstacle_stereo(&self) -> Option<u64> {
        self.fact(Ev::STOBS).filter(|f| f.f64(0) < 20.0).map(|f| f.seq)
    }

    // 40: an obstacle is passed

    /// The common part of the obstacle_passed_* rules: `FU within 500ms and PL
    /// within 500ms and LAOBN x3 and not STOBS(distance < 30.0)`.
    #[inline(always)]
    fn obstacle_passed(&self, fusion: Ev, plan: Ev) -> Option<u64> {
        let fu = self.within_500ms(fusion)?;
        let pl = self.within_500ms(plan)?;
        let la = self.run(Ev::LAOBN, 3)?;
        if self.stobs_within_30m().is_some() {
            return None;
        }
        Some(fu.max(pl).max(la))
    }

    /// obstacle_passed_straight: state == RO and FURS within 500ms and PLRS within 500ms and LAOBN x3
    /// and not STOBS(distance < 30.0) → RS
    fn obstacle_passed_straight(&self) -> Option<u64> {
        self.obstacle_passed(Ev::FURS, Ev::PLRS)
    }

    /// obstacle_passed_in_turn: state == RO and FURT within 500ms and PLRT within 500ms and LAOBN x3
    /// and not STOBS(distance < 30.0) → RT
    fn obstacle_passed_in_turn(&self) -> Option<u64> {
        self.obstacle_passed(Ev::FURT, Ev::PLRT)
    }

    /// obstacle_passed_at_branch: state == RO and FURB within 500ms and PLRB within 500ms and LAOBN x3
    /// and not STOBS(distance < 30.0) → RB
    fn obstacle_passed_at_branch(&self) -> Option<u64> {
        self.obstacle_passed(Ev::FURB, Ev::PLRB)
    }

    /// road_obstacle_off_road: state == RO and FUCO within 500ms and PLCO within 500ms → CO
    fn road_obstacle_off_road(&self) -> Option<u64> {
        let fu = self.within_500ms(Ev::FUCO)?;
        let pl = self.within_500ms(Ev::PLCO)?;
        Some(fu.max(pl))
    }

    /// terrain_obstacle_passed: state == CO and FUCN within 500ms and PLCN within 500ms and LAOBN x3
    /// and STOBN → CN
    fn terrain_obstacle_passed(&self) -> Option<u64> {
        let fu = self.within_500ms(Ev::FUCN)?;
        let pl = self.within_500ms(Ev::PLCN)?;
        let la = self.run(Ev::LAOBN, 3)?;
        let st = self.is(Ev::STOBN)?;
        Some(fu.max(pl).max(la).max(st))
    }

    /// terrain_obstacle_onto_road: state == CO and FURO within 500ms and PLRO within 500ms → RO
    fn terrain_obstacle_onto_road(&self) -> Option<u64> {
        let fu = self.within_500ms(Ev::FURO)?;
        let pl = self.within_500ms(Ev::PLRO)?;
        Some(fu.max(pl))
    }

    // 30: mission flow

    /// initialized: state == IT and SVRDY and TCHB and LOFIX(error < 0.5) x10 → RD
    fn initialized(&self) -> Option<u64> {
        let sv = self.is(Ev::SVRDY)?;
        let tc = self.is(Ev::TCHB)?;
        let lo = self.fact(Ev::LOFIX).filter(|f| f.f64(0) < 0.5 && f.run >= 10)?.seq;
        Some(sv.max(tc).max(lo))
    }

    /// start_on_road: state == RD and GPRS and RFRS x3 and LAOBN x3 and STOBN → RS
    fn start_on_road(&self) -> Option<u64> {
        let gp = self.is(Ev::GPRS)?;
        let rf = self.run(Ev::RFRS, 3)?;
        let la = self.run(Ev::LAOBN, 3)?;
        let st = self.is(Ev::STOBN)?;
        Some(gp.max(rf).max(la).max(st))
    }

    /// start_in_turn: state == RD and GPRT and RFRT x3 and LAOBN x3 and STOBN → RT
    fn start_in_turn(&self) -> Option<u64> {
        let gp = self.is(Ev::GPRT)?;
        let rf = self.run(Ev::RFRT, 3)?;
        let la = self.run(Ev::LAOBN, 3)?;
        let st = self.is(Ev::STOBN)?;
        Some(gp.max(rf).max(la).max(st))
    }

    /// start_cross_country: state == RD and GPCC and LAOBN x3 and STOBN x3 → CN
    fn start_cross_country(&self) -> Option<u64> {
        let gp = self.is(Ev::GPCC)?;
        let la = self.run(Ev::LAOBN, 3)?;
        let st = self.run(Ev::STOBN, 3)?;
        Some(gp.max(la).max(st))
    }

    // 30: road geometry

    /// road_straight: state in {RT, RB} and RFRS x3 → RS
    fn road_straight(&self) -> Option<u64> {
        self.run(Ev::RFRS, 3)
    }

    /// road_turn: state in {RS, RB} and RFRT(curvature >= 0.02) x2 → RT
    fn road_turn(&self) -> Option<u64> {
        self.fact(Ev::RFRT).filter(|f| f.f64(0) >= 0.02 && f.run >= 2).map(|f| f.seq)
    }

    /// road_branch: state in {RS, RT} and RFRB and GPRB → RB
    fn road_branch(&self) -> Option<u64> {
        let rf = self.is(Ev::RFRB)?;
        let gp = self.is(Ev::GPRB)?;
        Some(rf.max(gp))
    }

    /// road_ends: state in {RS, RT, RB} and GPCC and RFRN x3 → CN
    fn road_ends(&self) -> Option<u64> {
        let gp = self.is(Ev::GPCC)?;
        let rf = self.run(Ev::RFRN, 3)?;
        Some(gp.max(rf))
    }

    /// back_on_road: state == CN and GPRS and RFRS x3 → RS
    fn back_on_road(&self) -> Option<u64> {
        let gp = self.is(Ev::GPRS)?;
        let rf = self.run(Ev::RFRS, 3)?;
        Some(gp.max(rf))
    }
}

// ─── Test support: the `given` clause of situ tests ────────────────────────

#[cfg(test)]
impl Engine {
    /// `given state S`: sets the state without firing rules.
    pub fn given_state(&mut self, s: State) {
        self.state = s;
        self.unsettled = true;
    }

    /// `given E xN`: sets a fact stamped at `t` with run length `run`, without
    /// firing rules.
    pub fn given_fact(&mut self, e: &Event, run: u32) {
        self.insert(e);
        self.facts[e.agent as usize].run = run;
        self.unsettled = true;
    }

    /// Brings the network to rest now (after `given`), as §10.4 would.
    pub fn settle(&mut self) -> Result<State, CascadeError> {
        self.fired_len = 0;
        self.unsettled = false;
        self.rest()?;
        Ok(self.state)
    }

    /// The rules `select` offers in state `s` (bit per rule).
    pub fn offered_in(&mut self, s: State) -> u64 {
        self.state = s;
        self.offered.set(0);
        let _ = self.select();
        self.offered.get()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The order of `offer` on made-up recencies: salience, specificity,
    /// recency (0: matches no fact, last), declaration order.
    #[test]
    fn offer_orders_salience_specificity_recency_declaration() {
        use Rule::*;
        let mut engine = Engine::new();
        engine.state = State::RS;
        let best = |offers: &[(Rule, u64)]| {
            let mut p = Pick { best: None, recency: 0 };
            for &(rule, recency) in offers {
                engine.offer(&mut p, rule, |_| Some(recency));
            }
            p.best
        };
        assert_eq!(best(&[(RoadTurn, 9), (GoalReached, 1)]), Some(GoalReached));
        assert_eq!(best(&[(PlannerFailed, 9), (CollisionImminent, 1)]), Some(CollisionImminent));
        assert_eq!(best(&[(PlannerFailed, 0), (SafetyRadioLost, 5)]), Some(SafetyRadioLost));
        assert_eq!(best(&[(SafetyRadioLost, 5), (PlannerFailed, 0)]), Some(SafetyRadioLost));
        assert_eq!(best(&[(SafetyRadioLost, 0), (LadarSilent, 0)]), Some(LadarSilent));
        assert_eq!(best(&[(LadarSilent, 0), (SafetyRadioLost, 0)]), Some(LadarSilent));
        // A rule whose target is the current state is not activated.
        assert_eq!(best(&[(RoadStraight, 9)]), None);
    }
}
