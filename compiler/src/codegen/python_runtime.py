Json: _TypeAlias = _Union[None, bool, int, float, str, list["Json"], dict[str, "Json"]]
PayloadValue: _TypeAlias = _Union[float, int, bool, str]

# No status for this long: the Bulletinboard is gone, safe mode (seconds).
SAFE_MODE_AFTER = 0.6
# The most data kept for a step (keep-latest: the oldest is dropped).
INPUT_CAPACITY = 64


class Mode(_enum.Enum):
    """An agent's mode in a state (language reference §10.6)."""

    RUNNING = "running"
    WAITING = "waiting"
    SLEEPING = "sleeping"


@_dataclass(frozen=True)
class Action:
    """What the agent does: its mode, its function and its links as written."""

    mode: Mode
    function: str | None = None
    reads_from: tuple[str, ...] = ()
    sends_to: tuple[str, ...] = ()


@_dataclass(frozen=True)
class Transition:
    """An FSM transition: on a new state at rest in `on_states`, or on `on_event`."""

    source: str
    target: str
    on_states: tuple[str, ...] = ()
    on_event: str | None = None


@_dataclass(frozen=True)
class Fsm:
    """An agent's FSM: at most one transition per input, in source order."""

    initial: str
    actions: dict[str, Action]
    transitions: tuple[Transition, ...]

    def after_state(self, current: str, state: str) -> str:
        """The FSM state after the state at rest became `state`."""
        for t in self.transitions:
            if t.source == current and t.on_event is None and state in t.on_states:
                return t.target
        return current

    def after_event(self, current: str, event: str) -> str:
        """The FSM state after the agent reported `event`."""
        for t in self.transitions:
            if t.source == current and t.on_event == event:
                return t.target
        return current


@_dataclass(frozen=True)
class Event:
    """An event of this agent, its payload as the wire protocol writes it."""

    name: str
    payload: dict[str, PayloadValue]


@_dataclass(frozen=True)
class Datum:
    """A data message received on a link of the moment."""

    sender: str
    time_ns: int
    urgent: bool
    body: Json


def _f64(x: float) -> float | str:
    if _math.isnan(x):
        return "NaN"
    if _math.isinf(x):
        return "inf" if x > 0 else "-inf"
    return float(x)


def _i64(x: int) -> int:
    if isinstance(x, bool) or not -(2**63) <= int(x) < 2**63:
        raise ValueError(f"not an i64: {x!r}")
    return int(x)


# @@ GENERATED @@
class Step:
    """One step of the running cycle: what the agent sees and what it does."""

    def __init__(
        self,
        runner: Runner,
        state: str,
        mode: Mode,
        function: str | None,
        inputs: tuple[Datum, ...],
    ) -> None:
        self._runner = runner
        self.time_ns = _time.time_ns()
        self.state = state
        self.mode = mode
        self.function = function
        self.safe_mode = runner.safe_mode()
        self.fsm_state = runner.fsm_state
        self.inputs = inputs
        self.receivers = runner.receivers()

    def report(self, event: Event, urgent: bool = False) -> None:
        """Reports one of this agent's events to the Bulletinboard."""
        self._runner.report(event, urgent)

    def send(self, body: Json, urgent: bool = False) -> None:
        """Sends a datum along every link out of this agent active now."""
        self._runner.queue(None, body, urgent)

    def send_to(self, agent: str, body: Json, urgent: bool = False) -> None:
        """Sends a datum to one agent, if a link to it is active now."""
        self._runner.queue(agent, body, urgent)


class Runner:
    """The running cycle of this agent over a Zenoh session."""

    def __init__(self, handlers: Handlers, session: _zenoh.Session, robot: str) -> None:
        self.handlers = handlers
        self.session = session
        self.robot = robot
        self.state = INITIAL_STATE
        self.seq = -1
        self.fsm_state: str | None = FSM.initial if FSM is not None else None
        self.others = {name: fsm.initial for name, fsm in OTHER_FSMS.items()}
        self.states_seen: list[str] = []
        self.counters = {"steps": 0, "events": 0, "data_out": 0, "suppressed": 0}
        self.counters.update({"data_in": 0, "dropped": 0, "refused": 0})
        self._lock = _threading.Lock()
        self._wake = _threading.Event()
        self._last_status = _time.monotonic()
        self._seen_state = INITIAL_STATE
        self._inputs: list[Datum] = []
        self._outputs: list[tuple[str | None, Json, bool]] = []
        prefix = f"situ/{robot}"
        self._subscribers = [
            session.declare_subscriber(f"{prefix}/status", self._on_status),
            session.declare_subscriber(f"{prefix}/data/*/{AGENT}", self._on_data),
        ]
        for name in OTHER_FSMS:
            key = f"{prefix}/event/{name}"
            self._subscribers.append(session.declare_subscriber(key, self._on_event))

    # What arrives: status, data, the events of the FSM agents that read us.

    def _on_status(self, sample: _zenoh.Sample) -> None:
        try:
            msg = _json.loads(sample.payload.to_string())
            state, seq = msg["state"], int(msg["seq"])
            if msg.get("v") != PROTOCOL_VERSION or state not in STATES:
                raise ValueError(state)
        except (ValueError, KeyError, TypeError):
            self.counters["refused"] += 1
            return
        with self._lock:
            self._last_status = _time.monotonic()
            self.seq = seq
            if state != self.state:
                before = self.mode()
                self.state = state
                if FSM is not None and self.fsm_state is not None:
                    self.fsm_state = FSM.after_state(self.fsm_state, state)
                for name, fsm in OTHER_FSMS.items():
                    self.others[name] = fsm.after_state(self.others[name], state)
                if before == Mode.SLEEPING and self.mode() != Mode.SLEEPING:
                    self._inputs.clear()
                self._wake.set()

    def _on_data(self, sample: _zenoh.Sample) -> None:
        try:
            msg = _json.loads(sample.payload.to_string())
            if msg.get("v") != PROTOCOL_VERSION or msg["to"] != AGENT:
                raise ValueError(msg)
            urgent = bool(msg.get("urgent", False))
            datum = Datum(str(msg["from"]), int(msg["time_ns"]), urgent, msg["body"])
        except (ValueError, KeyError, TypeError):
            self.counters["refused"] += 1
            return
        with self._lock:
            if self.mode() == Mode.SLEEPING:
                self.counters["dropped"] += 1
                return
            if len(self._inputs) >= INPUT_CAPACITY:
                self._inputs.pop(len(self._inputs) - 1 if urgent else 0)
                self.counters["dropped"] += 1
            if urgent:
                self._inputs.insert(0, datum)
            else:
                self._inputs.append(datum)
            self.counters["data_in"] += 1
        if urgent or RATE_HZ is None:
            self._wake.set()

    def _on_event(self, sample: _zenoh.Sample) -> None:
        try:
            msg = _json.loads(sample.payload.to_string())
            agent, event = str(msg["agent"]), str(msg["event"])
        except (ValueError, KeyError, TypeError):
            return
        with self._lock:
            if agent in OTHER_FSMS:
                fsm, current = OTHER_FSMS[agent], self.others[agent]
                self.others[agent] = fsm.after_event(current, event)

    # The organisation of the moment.

    def safe_mode(self) -> bool:
        """Whether the Bulletinboard fell silent: every agent that would run waits."""
        return _time.monotonic() - self._last_status > SAFE_MODE_AFTER

    def action(self) -> Action | None:
        """The action of the moment (None: no table entry, asleep)."""
        if FSM is not None and self.fsm_state is not None:
            return FSM.actions[self.fsm_state]
        return TABLE.get(self.state) if TABLE is not None else None

    def mode(self) -> Mode:
        """The mode of the moment, safe mode applied."""
        action = self.action()
        if action is None:
            return Mode.SLEEPING
        if action.mode == Mode.RUNNING and self.safe_mode():
            return Mode.WAITING
        return action.mode

    def receivers(self) -> tuple[str, ...]:
        """The agents a datum sent now reaches (none unless running)."""
        if self.mode() != Mode.RUNNING:
            return ()
        out = set(LINKS_OUT.get(self.state, ()))
        for state, to, agent, fsm_state in FSM_LINKS_OUT:
            now = self.fsm_state if agent == AGENT else self.others.get(agent)
            if state == self.state and now == fsm_state:
                out.add(to)
        return tuple(sorted(out))

    # What the agent does.

    def report(self, event: Event, urgent: bool = False) -> None:
        """Puts an event on the agent's event key; its FSM sees it first."""
        if event.name not in EVENTS:
            raise ValueError(f"`{event.name}` is not an event of {AGENT}")
        with self._lock:
            if FSM is not None and self.fsm_state is not None:
                self.fsm_state = FSM.after_event(self.fsm_state, event.name)
        msg = {
            "v": PROTOCOL_VERSION,
            "agent": AGENT,
            "event": event.name,
            "time_ns": _time.time_ns(),
            "payload": event.payload,
            "urgent": urgent,
        }
        self.session.put(f"situ/{self.robot}/event/{AGENT}", _json.dumps(msg))
        self.counters["events"] += 1

    def queue(self, to: str | None, body: Json, urgent: bool) -> None:
        """Keeps a datum to send at the end of the step."""
        self._outputs.append((to, body, urgent))

    def _flush(self, mode: Mode) -> None:
        outputs, self._outputs = self._outputs, []
        with self._lock:
            receivers = self.receivers()
        for to, body, urgent in outputs:
            targets = receivers if to is None else (to,) if to in receivers else ()
            if mode != Mode.RUNNING or not targets:
                self.counters["suppressed"] += 1
                continue
            for target in targets:
                msg = {
                    "v": PROTOCOL_VERSION,
                    "from": AGENT,
                    "to": target,
                    "time_ns": _time.time_ns(),
                    "urgent": urgent,
                    "body": body,
                }
                key = f"situ/{self.robot}/data/{AGENT}/{target}"
                self.session.put(key, _json.dumps(msg))
                self.counters["data_out"] += 1

    def step_once(self) -> bool:
        """One step of the running cycle; False when the agent sleeps."""
        with self._lock:
            state, seq = self.state, self.seq
            changed = state != self._seen_state
            self._seen_state = state
        if changed:
            self.states_seen.append(state)
            self.handlers.on_status(state, seq)
        with self._lock:
            mode = self.mode()
            action = self.action()
            if mode == Mode.SLEEPING:
                return False
            inputs, self._inputs = tuple(self._inputs), []
        function = action.function if action is not None else None
        step = Step(self, state, mode, function, inputs)
        _dispatch(self.handlers, step)
        self._flush(mode)
        self.counters["steps"] += 1
        return True

    def loop(
        self,
        duration: float | None = None,
        stop: _Callable[[Runner], bool] | None = None,
    ) -> None:
        """Steps at RATE_HZ (or when data or a new status arrives) until
        `duration` seconds have passed or `stop(self)` is true."""
        end = None if duration is None else _time.monotonic() + duration
        period = 1.0 / RATE_HZ if RATE_HZ else None
        next_step = _time.monotonic()
        while end is None or _time.monotonic() < end:
            if stop is not None and stop(self):
                return
            if period is not None:
                _time.sleep(max(0.0, next_step - _time.monotonic()))
                next_step += period
                self._wake.clear()
                self.step_once()
            elif self._wake.wait(0.05):
                self._wake.clear()
                self.step_once()


def run(
    handlers: Handlers,
    robot: str,
    connect: list[str] | None = None,
    listen: list[str] | None = None,
    duration: float | None = None,
    stop: _Callable[[Runner], bool] | None = None,
) -> Runner:
    """Joins the stack `robot` over Zenoh (a peer, multicast scouting off)
    and runs the agent until `duration` seconds or `stop`; the runner."""
    conf = _zenoh.Config()
    conf.insert_json5("mode", '"peer"')
    conf.insert_json5("connect/endpoints", _json.dumps(connect or []))
    conf.insert_json5("listen/endpoints", _json.dumps(listen or []))
    conf.insert_json5("scouting/multicast/enabled", "false")
    with _zenoh.open(conf) as session:
        runner = Runner(handlers, session, robot)
        runner.loop(duration, stop)
    return runner
