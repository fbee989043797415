//! The declarations of `rules/outdoor.situ`, hard-coded: its states, the agents
//! that report events (with their `stale after`), and each event's payload fields
//! in declaration order.

/// The system states of `outdoor.situ`, in declaration order.
///
/// A copy of `situ_sim::baseline::outdoor::State` (both copy the rules),
/// kept here on purpose: this crate is the benchmark's hand-written
/// practical limit and has no dependency at all; taking the enum from
/// `situ-sim` would build the sim, the runtime and the compiler into the
/// benchmark, and the sim's enum (ordered, serialized, with LPL's plans per
/// state) is not the `repr(u8)` one the matcher indexes by.
#[allow(clippy::upper_case_acronyms)]
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
#[repr(u8)]
pub enum State {
    IT,
    RD,
    RS,
    RT,
    RB,
    RO,
    CN,
    CO,
    GL,
    EM,
    SP,
}

impl State {
    /// Every state, in declaration order.
    #[cfg(test)]
    pub const ALL: [State; 11] = [
        State::IT,
        State::RD,
        State::RS,
        State::RT,
        State::RB,
        State::RO,
        State::CN,
        State::CO,
        State::GL,
        State::EM,
        State::SP,
    ];

    /// The `initial` state.
    pub const INITIAL: State = State::IT;

    /// `final` states end a mission (GL, SP).
    #[inline(always)]
    pub fn is_final(self) -> bool {
        matches!(self, State::GL | State::SP)
    }

    pub fn name(self) -> &'static str {
        match self {
            State::IT => "IT",
            State::RD => "RD",
            State::RS => "RS",
            State::RT => "RT",
            State::RB => "RB",
            State::RO => "RO",
            State::CN => "CN",
            State::CO => "CO",
            State::GL => "GL",
            State::EM => "EM",
            State::SP => "SP",
        }
    }
}

/// The agents of `outdoor.situ` that declare events. (`Mapper` and `Recorder`
/// declare none: they never have a fact, and no rule names them.)
#[allow(clippy::upper_case_acronyms)]
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
#[repr(u8)]
pub enum Agent {
    RFCCD,
    STCCD,
    LADAR,
    Localization,
    Fusion,
    GPL,
    LPL,
    Drive,
    Supervisor,
    TeleControl,
}

/// How many agents have a fact slot.
pub const AGENTS: usize = 10;

const MS: u64 = 1_000_000;

/// The agents with `stale after D`, and D in nanoseconds.
pub const STALE_AFTER: [(Agent, u64); 5] = [
    (Agent::RFCCD, 400 * MS),
    (Agent::STCCD, 500 * MS),
    (Agent::LADAR, 300 * MS),
    (Agent::Localization, 200 * MS),
    (Agent::TeleControl, 1000 * MS),
];

/// `within 500ms`, the only window of the rules.
pub const WITHIN_500MS: u64 = 500 * MS;
/// `within 100ms` (emergency_halted: a fresh DRSTOP).
pub const WITHIN_100MS: u64 = 100 * MS;

/// The events of `outdoor.situ`, grouped by agent, in declaration order.
#[allow(clippy::upper_case_acronyms)]
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
#[repr(u8)]
pub enum Ev {
    // RFCCD
    RFRS,
    RFRT,
    RFRB,
    RFRN,
    // STCCD
    STOBS,
    STOBN,
    // LADAR
    LAOBS,
    LAOBN,
    // Localization
    LOFIX,
    LOLOST,
    // Fusion
    FURS,
    FURT,
    FURB,
    FURO,
    FUCN,
    FUCO,
    // GPL
    GPRS,
    GPRT,
    GPRB,
    GPCC,
    GPGL,
    // LPL
    PLRS,
    PLRT,
    PLRB,
    PLRO,
    PLCN,
    PLCO,
    PLF,
    // Drive
    DRSTOP,
    DRFAULT,
    // Supervisor
    SVRDY,
    SVSTOP,
    // TeleControl
    TCHB,
    TCTAKE,
}

/// The type of a payload field.
#[derive(Clone, Copy, Debug)]
pub enum FieldType {
    F64,
    I64,
    /// An enumerated field: its symbols in declaration order.
    Sym(&'static [&'static str]),
}

const SIDE: FieldType = FieldType::Sym(&["left", "right"]);
const PLF_REASON: FieldType = FieldType::Sym(&["no_path", "blocked", "timeout"]);
const SVSTOP_REASON: FieldType = FieldType::Sym(&["operator", "stuck", "danger"]);

impl Ev {
    /// The event of a name, as written in a stream.
    pub fn from_name(name: &str) -> Option<Ev> {
        Some(match name {
            "RFRS" => Ev::RFRS,
            "RFRT" => Ev::RFRT,
            "RFRB" => Ev::RFRB,
            "RFRN" => Ev::RFRN,
            "STOBS" => Ev::STOBS,
            "STOBN" => Ev::STOBN,
            "LAOBS" => Ev::LAOBS,
            "LAOBN" => Ev::LAOBN,
            "LOFIX" => Ev::LOFIX,
            "LOLOST" => Ev::LOLOST,
            "FURS" => Ev::FURS,
            "FURT" => Ev::FURT,
            "FURB" => Ev::FURB,
            "FURO" => Ev::FURO,
            "FUCN" => Ev::FUCN,
            "FUCO" => Ev::FUCO,
            "GPRS" => Ev::GPRS,
            "GPRT" => Ev::GPRT,
            "GPRB" => Ev::GPRB,
            "GPCC" => Ev::GPCC,
            "GPGL" => Ev::GPGL,
            "PLRS" => Ev::PLRS,
            "PLRT" => Ev::PLRT,
            "PLRB" => Ev::PLRB,
            "PLRO" => Ev::PLRO,
            "PLCN" => Ev::PLCN,
            "PLCO" => Ev::PLCO,
            "PLF" => Ev::PLF,
            "DRSTOP" => Ev::DRSTOP,
            "DRFAULT" => Ev::DRFAULT,
            "SVRDY" => Ev::SVRDY,
            "SVSTOP" => Ev::SVSTOP,
            "TCHB" => Ev::TCHB,
            "TCTAKE" => Ev::TCTAKE,
            _ => return None,
        })
    }

    /// The agent that declares the event.
    #[inline(always)]
    pub fn agent(self) -> Agent {
        use Ev::*;
        match self {
            RFRS | RFRT | RFRB | RFRN => Agent::RFCCD,
            STOBS | STOBN => Agent::STCCD,
            LAOBS | LAOBN => Agent::LADAR,
            LOFIX | LOLOST => Agent::Localization,
            FURS | FURT | FURB | FURO | FUCN | FUCO => Agent::Fusion,
            GPRS | GPRT | GPRB | GPCC | GPGL => Agent::GPL,
            PLRS | PLRT | PLRB | PLRO | PLCN | PLCO | PLF => Agent::LPL,
            DRSTOP | DRFAULT => Agent::Drive,
            SVRDY | SVSTOP => Agent::Supervisor,
            TCHB | TCTAKE => Agent::TeleControl,
        }
    }

    /// The payload fields, in the order the event declares them (and the
    /// stream writes them).
    pub fn fields(self) -> &'static [FieldType] {
        use FieldType::*;
        match self {
            Ev::RFRT => &[F64, SIDE],       // curvature, side
            Ev::RFRB => &[F64],             // distance
            Ev::STOBS => &[F64, F64],       // distance, width
            Ev::LAOBS => &[F64, F64],       // distance, height
            Ev::LOFIX => &[F64],            // error
            Ev::FURO | Ev::FUCO => &[F64],  // distance
            Ev::GPGL => &[F64],             // remaining
            Ev::PLF => &[PLF_REASON],       // reason
            Ev::DRFAULT => &[I64],          // code
            Ev::SVSTOP => &[SVSTOP_REASON], // reason
            _ => &[],
        }
    }
}

/// One payload value. The stream gives each in its declared type; a field the
/// event does not have is `None`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Value {
    None,
    F64(f64),
    // The integer and symbol payloads are kept as the stream gives them, though
    // no rule of outdoor.situ tests them (DRFAULT's code, RFRT's side, the reasons).
    #[allow(dead_code)]
    I64(i64),
    /// A symbol: its index among the field's symbols.
    #[allow(dead_code)]
    Sym(u8),
}

impl Value {
    /// The value of an `f64` field. Rules only read `f64` fields of events that
    /// have them; anything else gives NaN, which satisfies no comparison.
    #[inline(always)]
    pub fn f64(self) -> f64 {
        match self {
            Value::F64(x) => x,
            _ => f64::NAN,
        }
    }
}

/// One event of the stream, parsed: small and `Copy`.
#[derive(Clone, Copy, Debug)]
pub struct Event {
    /// Timestamp in nanoseconds.
    pub t: u64,
    pub agent: Agent,
    pub ev: Ev,
    /// The line of the stream file (for error messages).
    pub line: u32,
    /// The payload in declaration order (at most two fields in outdoor.situ).
    pub p: [Value; 2],
}
