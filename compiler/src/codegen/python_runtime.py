Json: _TypeAlias = _Union[None, bool, int, float, str, list["Json"], dict[str, "Json"]]
PayloadValue: _TypeAlias = _Union[float, int, bool, str]

# No status for this long: the Bulletinboard is gone, safe mode (seconds).
SAFE_MODE_AFTER = 0.6
# The most data kept for a step (keep-latest: the oldest is dropped).
INPUT_CAPACITY = 64
# The most events held while the Bulletinboard is not there (before its first
# status, and in safe mode): the oldest is dropped and counted (`held_dropped`).
HELD_CAPACITY = 256


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


class AgentRunner(_Protocol):
    """What `run_all` drives: the `Runner` of any generated agent module."""

    agent: str
    finished: bool
    states_seen: list[str]
    counters: dict[str, int]

    def loop(
        self,
        duration: float | None = None,
        stop: _Callable[[_Any], bool] | None = None,
        halt: _threading.Event | None = None,
    ) -> None: ...


class Joinable(_Protocol):
    """The handlers of any generated agent module (for `run_all`)."""

    def _situ_agent(self) -> str: ...

    def _situ_runner(self, session: _zenoh.Session, robot: str) -> AgentRunner: ...


class Runner:
    """The running cycle of this agent over a Zenoh session.

    It starts in safe mode (no status yet: an agent that would run waits, and
    its events are held) and follows the Bulletinboard's status from its
    first one; it ends at a final state (`finished`)."""

    def __init__(self, handlers: Handlers, session: _zenoh.Session, robot: str) -> None:
        self.agent = AGENT
        self.handlers = handlers
        self.session = session
        self.robot = robot
        self.state = INITIAL_STATE
        self.seq = -1
        # The highest epoch of a leading Bulletinboard seen, and its name: a
        # status of a lower epoch is an old leader's and is ignored.
        self.epoch = 0
        self.board: str | None = None
        self.finished = False
        self.fsm_state: str | None = FSM.initial if FSM is not None else None
        self.others = {name: fsm.initial for name, fsm in OTHER_FSMS.items()}
        self.states_seen: list[str] = []
        self.counters = {"steps": 0, "events": 0, "data_out": 0, "suppressed": 0}
        self.counters.update({"data_in": 0, "dropped": 0, "refused": 0})
        self.counters.update({"held": 0, "held_dropped": 0, "restarts": 0})
        self.counters.update({"old_epoch": 0})
        self._lock = _threading.Lock()
        self._wake = _threading.Event()
        self._heard = False
        self._last_status = _time.monotonic()
        self._statuses: list[tuple[str, int, bool]] = []
        self._safe_told: bool | None = None  # what on_safe_mode was told
        self._held: _deque[tuple[Event, bool]] = _deque()
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
            epoch, board = int(msg.get("epoch", 0)), msg.get("board")
            if msg.get("v") != PROTOCOL_VERSION or state not in STATES or epoch < 0:
                raise ValueError(state)
            if board is not None and not isinstance(board, str):
                raise ValueError(board)
        except (ValueError, KeyError, TypeError):
            self.counters["refused"] += 1
            return
        with self._lock:
            if epoch < self.epoch:
                # An old leader's: another Bulletinboard leads now. Not
                # followed, and not a sign of life (safe mode still counts).
                self.counters["old_epoch"] += 1
                return
            was_safe = self.safe_mode()
            self._last_status = _time.monotonic()
            # A new status: the first, a change, a new leader (a higher
            # epoch), or a Bulletinboard that restarted (its `seq` starts
            # again in the same epoch); not a repetition.
            takeover = epoch > self.epoch
            new = not self._heard or takeover or seq != self.seq or state != self.state
            restart = self._heard and not takeover and seq < self.seq
            self._heard = True
            self.seq = seq
            self.epoch, self.board = epoch, board
            if new:
                self._statuses.append((state, seq, restart))
            if state != self.state:
                before = self.mode()
                self.state = state
                if FSM is not None and self.fsm_state is not None:
                    self.fsm_state = FSM.after_state(self.fsm_state, state)
                for name, fsm in OTHER_FSMS.items():
                    self.others[name] = fsm.after_state(self.others[name], state)
                if before == Mode.SLEEPING and self.mode() != Mode.SLEEPING:
                    self._inputs.clear()
        if new or was_safe:
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
        """Whether the Bulletinboard is not there (no status yet, or none for
        SAFE_MODE_AFTER seconds): every agent that would run waits."""
        if not self._heard:
            return True
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
        """Puts an event on the agent's event key; its FSM sees it first.
        While the Bulletinboard is not there the event is held (at most
        HELD_CAPACITY, the oldest dropped and counted) and sent, in order,
        once a status shows it is back."""
        if event.name not in EVENTS:
            raise ValueError(f"`{event.name}` is not an event of {AGENT}")
        with self._lock:
            if FSM is not None and self.fsm_state is not None:
                self.fsm_state = FSM.after_event(self.fsm_state, event.name)
            if self.safe_mode() or self._held:
                if len(self._held) >= HELD_CAPACITY:
                    self._held.popleft()
                    self.counters["held_dropped"] += 1
                self._held.append((event, urgent))
                self.counters["held"] += 1
                return
        self._put_event(event, urgent)

    def _put_event(self, event: Event, urgent: bool) -> None:
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

    def held(self) -> int:
        """How many events wait for the Bulletinboard now."""
        with self._lock:
            return len(self._held)

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

    def follow(self) -> None:
        """Calls the hooks for what the status said since the last call
        (`on_board_restart`, `on_status` for every new status, `on_safe_mode`
        on entering and leaving safe mode), then sends the held events once
        the Bulletinboard is there."""
        if self._safe_told is None:
            # The runner starts in safe mode, whether or not a status came
            # before this first call.
            self._safe_told = True
            self.handlers.on_safe_mode(True)
        with self._lock:
            statuses, self._statuses = self._statuses, []
            safe = self.safe_mode()
        for state, seq, restart in statuses:
            if restart:
                self.counters["restarts"] += 1
                self.handlers.on_board_restart()
            self.states_seen.append(state)
            self.handlers.on_status(state, seq)
            if state in FINAL_STATES:
                self.finished = True
        if safe != self._safe_told:
            self._safe_told = safe
            self.handlers.on_safe_mode(safe)
        while not safe:
            with self._lock:
                if not self._held:
                    return
                event, urgent = self._held.popleft()
            self._put_event(event, urgent)

    def step_once(self) -> bool:
        """One step of the running cycle; False when the agent sleeps."""
        self.follow()
        with self._lock:
            state = self.state
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
        stop: _Callable[[_Any], bool] | None = None,
        halt: _threading.Event | None = None,
    ) -> None:
        """Steps at RATE_HZ (or when data or a new status arrives) until a
        final state, `duration` seconds, `stop(self)` or `halt` is set."""
        end = None if duration is None else _time.monotonic() + duration
        period = 1.0 / RATE_HZ if RATE_HZ else None
        next_step = _time.monotonic()
        while end is None or _time.monotonic() < end:
            self.follow()
            if self.finished or (halt is not None and halt.is_set()):
                return
            if stop is not None and stop(self):
                return
            if period is not None:
                wait = next_step - _time.monotonic()
                if wait > 0:
                    # Short waits: the hooks and held events are not late.
                    self._wake.wait(min(wait, 0.05))
                    self._wake.clear()
                    continue
                next_step += period
                self._wake.clear()
                self.step_once()
            elif self._wake.wait(0.05):
                self._wake.clear()
                self.step_once()


def deployment_config(
    path: str,
    process: str | None,
    agents: _Sequence[str],
) -> tuple[str, dict[str, _Any]]:
    """The robot and the Zenoh configuration of one process of a deployment
    file, made as situ makes it (`bus-zenoh/src/deploy.rs`): mode, endpoints,
    reconnection every 100-500 ms, multicast scouting off, gossip on, TLS with
    client certificates and access control. Without `process`: the process
    that runs all of `agents`."""
    try:
        toml = _importlib.import_module("tomllib")
    except ModuleNotFoundError:  # Python 3.10: the `tomli` package
        toml = _importlib.import_module("tomli")
    with open(path, "rb") as f:
        d = toml.load(f)
    where = _os.path.dirname(path)
    procs: list[dict[str, _Any]] = d.get("process", [])
    names = [str(p.get("name")) for p in procs]
    if process is None:
        runs = [p for p in procs if all(a in p.get("agents", []) for a in agents)]
        if not runs:
            raise ValueError(f"{path}: no process runs {', '.join(agents)}")
        p = runs[0]
    else:
        found = [p for p in procs if p.get("name") == process]
        if not found:
            have = ", ".join(names)
            raise ValueError(f"{path}: no process `{process}` (it has {have})")
        p = found[0]
    for a in agents:
        if a not in p.get("agents", []):
            raise ValueError(f"{path}: process `{p['name']}` does not run `{a}`")
    mode = p.get("mode", "peer")
    if mode not in ("peer", "client", "router"):
        raise ValueError(f"{path}: process `{p['name']}`: `mode = {mode!r}`")
    cfg: dict[str, _Any] = {
        "mode": mode,
        "listen": {"endpoints": list(p.get("listen", []))},
        "connect": {
            "endpoints": list(p.get("connect", [])),
            "retry": {
                "period_init_ms": 100,
                "period_max_ms": 500,
                "period_increase_factor": 2,
            },
        },
        "scouting": {"multicast": {"enabled": False}, "gossip": {"enabled": True}},
    }
    if mode == "client":
        cfg["connect"]["timeout_ms"] = -1
        cfg["connect"]["exit_on_failure"] = False
    tls = d.get("tls")
    if tls is not None and "cert" in p and "key" in p:

        def full(f: str) -> str:
            return f if _os.path.isabs(f) else _os.path.join(where, f)

        cert, key = full(p["cert"]), full(p["key"])
        cfg["transport"] = {
            "link": {
                "tls": {
                    "root_ca_certificate": full(tls["ca"]),
                    "listen_private_key": key,
                    "listen_certificate": cert,
                    "connect_private_key": key,
                    "connect_certificate": cert,
                    "enable_mtls": True,
                    "verify_name_on_connect": False,
                }
            }
        }
        cfg["access_control"] = _access_control(str(d["robot"]), procs)
    return str(d["robot"]), cfg


def _access_control(robot: str, procs: list[dict[str, _Any]]) -> dict[str, _Any]:
    board = [str(p["name"]) for p in procs if p.get("board", False)]
    status = [f"situ/{robot}/status"]
    streams = [f"situ/{robot}/event/**", f"situ/{robot}/data/**"]
    declares = [
        "declare_subscriber",
        "declare_liveliness_subscriber",
        "liveliness_token",
        "declare_queryable",
    ]
    both = ["ingress", "egress"]
    boards = [f"situ/{robot}/board/**"]
    return {
        "enabled": True,
        "default_permission": "deny",
        "rules": [
            _rule("status_in", ["put"], ["ingress"], status),
            _rule("status_out", ["put"], ["egress"], status),
            _rule("streams", ["put"], both, streams),
            _rule("boards", ["put", "query", "reply"], both, boards),
            _rule("subscribe", declares, both, ["**"]),
        ],
        "subjects": [
            {"id": "board", "cert_common_names": board},
            {"id": "members", "cert_common_names": [str(p["name"]) for p in procs]},
        ],
        "policies": [
            {
                "id": "board_status",
                "rules": ["status_in", "boards"],
                "subjects": ["board"],
            },
            {
                "id": "members_streams",
                "rules": ["status_out", "streams", "subscribe"],
                "subjects": ["members"],
            },
        ],
    }


def _rule(
    id: str,
    messages: list[str],
    flows: list[str],
    keys: list[str],
) -> dict[str, _Any]:
    return {
        "id": id,
        "messages": messages,
        "flows": flows,
        "permission": "allow",
        "key_exprs": keys,
    }


def _argv(flag: str) -> str | None:
    """The value of `--flag V` or `--flag=V` on the command line."""
    args = _sys.argv[1:]
    for i, a in enumerate(args):
        if a == flag and i + 1 < len(args):
            return args[i + 1]
        if a.startswith(flag + "="):
            return a[len(flag) + 1 :]
    return None


def run_all(
    agents: _Sequence[Joinable],
    robot: str | None = None,
    connect: list[str] | None = None,
    listen: list[str] | None = None,
    duration: float | None = None,
    stop: _Callable[[_Any], bool] | None = None,
    deploy: str | None = None,
    process: str | None = None,
) -> list[AgentRunner]:
    """Runs several agents (the handlers of generated modules) in this
    process, one thread each, on one Zenoh session; each ends at a final
    state, after `duration` seconds or when `stop(runner)` is true.

    With a deployment file (`deploy`, or `--deploy D` on the command line)
    the session is the process's (`process`, `--process P`, or the one that
    runs these agents) as situ makes it, and the robot is the file's;
    without one, a peer that connects to `connect` and listens on `listen`,
    multicast scouting off, with situ's reconnection settings."""
    deploy = deploy if deploy is not None else _argv("--deploy")
    process = process if process is not None else _argv("--process")
    if deploy is not None:
        names = [a._situ_agent() for a in agents]
        file_robot, cfg = deployment_config(deploy, process, names)
        if robot is not None and robot != file_robot:
            raise ValueError(f"robot {robot!r}, but {deploy} says {file_robot!r}")
        robot = file_robot
    elif robot is None:
        raise ValueError("give the robot (or a deployment file)")
    else:
        cfg = {
            "mode": "peer",
            "listen": {"endpoints": list(listen or [])},
            "connect": {
                "endpoints": list(connect or []),
                "retry": {
                    "period_init_ms": 100,
                    "period_max_ms": 500,
                    "period_increase_factor": 2,
                },
            },
            "scouting": {"multicast": {"enabled": False}},
        }
    conf = _zenoh.Config.from_json5(_json.dumps(cfg))
    halt = _threading.Event()
    errors: list[BaseException] = []
    with _zenoh.open(conf) as session:
        runners = [a._situ_runner(session, robot) for a in agents]
        seen = [r.agent for r in runners]
        if len(set(seen)) != len(seen):
            raise ValueError(f"an agent given twice: {seen}")

        def drive(r: AgentRunner) -> None:
            try:
                r.loop(duration, stop, halt)
            except BaseException as e:
                errors.append(e)
                halt.set()

        threads = [_threading.Thread(target=drive, args=(r,)) for r in runners]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
    if errors:
        raise errors[0]
    return runners


def run(
    handlers: Handlers,
    robot: str | None = None,
    connect: list[str] | None = None,
    listen: list[str] | None = None,
    duration: float | None = None,
    stop: _Callable[[Runner], bool] | None = None,
    deploy: str | None = None,
    process: str | None = None,
) -> Runner:
    """Runs this agent alone (see `run_all`); the runner."""
    runners = run_all(
        [handlers], robot, connect, listen, duration, stop, deploy, process
    )
    runner = runners[0]
    assert isinstance(runner, Runner)
    return runner
