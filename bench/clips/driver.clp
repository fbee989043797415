;;; ═══════════════════════════════════════════════════════════════════════
;;;  driver.clp: reads a `.events` stream (bench/README.md) and runs it
;;;  through the rules of outdoor.clp with the semantics of
;;;  docs/language.md 10.1-10.4 and the benchmark's mission resets.
;;;
;;;  Load outdoor.clp first, then this file, then call
;;;      (main "STREAM.events" "STATES.out")
;;;  which writes the state sequence to STATES.out and prints one line
;;;      RESULT <events> <seconds> <state_changes>
;;;  to standard output (run.sh turns it into the JSON line). `seconds` is
;;;  the difference of CLIPS's (time) around the read-and-process loop; in
;;;  Debian's CLIPS 6.30 build (time) is the process's CPU time (clock()),
;;;  which for this single-threaded loop over a cached file equals its wall
;;;  time on an idle machine. Reading and parsing the lines is included.
;;;
;;;  Per event `T NAME V...` of agent A (index 0-based in the stream):
;;;   0. if the previous event left a final state (GL, SP), reset first:
;;;      the initial state IT, no facts (now is kept);
;;;   1. now = max(now, T); the clock fact is modified if now moved;
;;;   2. expire every agent with `stale after D` whose fact is older than D
;;;      (now - t > D, strictly): retract its fact, assert (stale A); if any
;;;      expired, run to rest (if none did, the network is still at rest:
;;;      advancing now can only close `within` windows, never activate);
;;;   3. replace A's fact: run = old run + 1 if A's old (live) fact is the
;;;      same event, else 1; retract (stale A) if present; run to rest;
;;;   4. if the state differs from the state before the event (after a
;;;      reset: IT), write "INDEX STATE" to the states file.
;;;  A rest is (run 65); more than 64 firings in one rest is an error (exit
;;;  code 2). An agent that never reported has no fact and is not stale.
;;; ═══════════════════════════════════════════════════════════════════════

;;; ─── Static tables ──────────────────────────────────────────────────────
;;; Agents that report events, numbered 1..10; the ones with `stale after`
;;; first (1..5), in increasing order of their stale time.

(defglobal
   ?*agents*      = (create$ Localization LADAR RFCCD STCCD TeleControl
                             Fusion GPL LPL Drive Supervisor)
   ?*n-stale*     = 5
   ;; `stale after` of agents 1..5, in ns
   ?*stale-after* = (create$ 200000000 300000000 400000000 500000000 1000000000)
   ;; every event name, and the number of the agent that declares it
   ?*events*      = (create$ LOFIX LOLOST
                             LAOBS LAOBN
                             RFRS RFRT RFRB RFRN
                             STOBS STOBN
                             TCHB TCTAKE
                             FURS FURT FURB FURO FUCN FUCO
                             GPRS GPRT GPRB GPCC GPGL
                             PLRS PLRT PLRB PLRO PLCN PLCO PLF
                             DRSTOP DRFAULT
                             SVRDY SVSTOP)
   ?*event-agent* = (create$ 1 1
                             2 2
                             3 3 3 3
                             4 4
                             5 5
                             6 6 6 6 6 6
                             7 7 7 7 7
                             8 8 8 8 8 8 8
                             9 9
                             10 10)
   ?*never*       = 9223372036854775807   ; the largest integer
)

;;; ─── Working state of the driver ────────────────────────────────────────

(defglobal
   ?*now*      = 0
   ?*clock*    = FALSE     ; the clock fact
   ?*fact*     = (create$) ; per agent: its latest live fact, or FALSE
   ?*stale*    = (create$) ; per agent 1..5: its (stale A) fact, or FALSE
   ;; a lower bound of the time after which some live fact may expire:
   ;; <= min(t + D) over the live facts of agents 1..5. A report only moves
   ;; an agent's own expiry later, so the bound stays valid without being
   ;; recomputed on every event; expire-agents recomputes it exactly.
   ?*deadline* = 9223372036854775807
   ?*prev*     = IT        ; the state at rest before the current event
   ?*changes*  = 0         ; lines written to the states file
)

;;; ─── Rest ───────────────────────────────────────────────────────────────

(deffunction to-rest (?index)
   (bind ?*firings* 0)
   (bind ?*fired* (create$))
   (run 65)
   (if (> ?*firings* 64) then
      (printout t "ERROR: event " ?index ": more than 64 firings without rest: "
                (implode$ ?*fired*) crlf)
      (close)
      (exit 2)))

;;; ─── Missions ───────────────────────────────────────────────────────────

;; The initial state with no facts; now is kept.
(deffunction new-mission ()
   (reset)                                   ; retracts every fact
   (bind ?*clock* (assert (clock (now ?*now*))))
   (assert (system (state IT)))
   (bind ?*state* IT)
   (bind ?*prev* IT)
   (bind ?*fact* (create$ FALSE FALSE FALSE FALSE FALSE
                          FALSE FALSE FALSE FALSE FALSE))
   (bind ?*stale* (create$ FALSE FALSE FALSE FALSE FALSE))
   (bind ?*deadline* ?*never*))

;;; ─── Staleness ──────────────────────────────────────────────────────────

;; Expires every agent whose fact is older than its stale time; returns
;; TRUE if any did. Recomputes ?*deadline* exactly.
(deffunction expire-agents ()
   (bind ?expired FALSE)
   (bind ?deadline ?*never*)
   (loop-for-count (?k 1 ?*n-stale*)
      (bind ?f (nth$ ?k ?*fact*))
      (if ?f then
         (bind ?d (nth$ ?k ?*stale-after*))
         (bind ?t (fact-slot-value ?f t))
         (if (> (- ?*now* ?t) ?d)
          then
            (retract ?f)
            (bind ?*fact* (replace$ ?*fact* ?k ?k FALSE))
            (bind ?*stale* (replace$ ?*stale* ?k ?k
                                     (assert (stale (nth$ ?k ?*agents*)))))
            (bind ?expired TRUE)
          else
            (bind ?deadline (min ?deadline (+ ?t ?d))))))
   (bind ?*deadline* ?deadline)
   ?expired)

;;; ─── The new fact ───────────────────────────────────────────────────────

;; Asserts the fact of event ?e with its payload from the exploded line ?l
;; (T NAME V1 V2): the payload fields in the order the event declares them.
(deffunction assert-event (?e ?run ?t ?l)
   (switch ?e
      ;; the most frequent first (Localization and Drive report at 50 Hz)
      (case LOFIX   then (assert (LOFIX (run ?run) (t ?t) (error (nth$ 3 ?l)))))
      (case DRSTOP  then (assert (DRSTOP (run ?run) (t ?t))))
      (case RFRS    then (assert (RFRS (run ?run) (t ?t))))
      (case LAOBN   then (assert (LAOBN (run ?run) (t ?t))))
      (case LAOBS   then (assert (LAOBS (run ?run) (t ?t) (distance (nth$ 3 ?l))
                                        (height (nth$ 4 ?l)))))
      (case STOBN   then (assert (STOBN (run ?run) (t ?t))))
      (case STOBS   then (assert (STOBS (run ?run) (t ?t) (distance (nth$ 3 ?l))
                                        (width (nth$ 4 ?l)))))
      (case TCHB    then (assert (TCHB (run ?run) (t ?t))))
      (case LOLOST  then (assert (LOLOST (run ?run) (t ?t))))
      (case DRFAULT then (assert (DRFAULT (run ?run) (t ?t) (code (nth$ 3 ?l)))))
      (case RFRT    then (assert (RFRT (run ?run) (t ?t) (curvature (nth$ 3 ?l))
                                       (side (nth$ 4 ?l)))))
      (case RFRB    then (assert (RFRB (run ?run) (t ?t) (distance (nth$ 3 ?l)))))
      (case RFRN    then (assert (RFRN (run ?run) (t ?t))))
      (case FURS    then (assert (FURS (run ?run) (t ?t))))
      (case FURT    then (assert (FURT (run ?run) (t ?t))))
      (case FURB    then (assert (FURB (run ?run) (t ?t))))
      (case FURO    then (assert (FURO (run ?run) (t ?t) (distance (nth$ 3 ?l)))))
      (case FUCN    then (assert (FUCN (run ?run) (t ?t))))
      (case FUCO    then (assert (FUCO (run ?run) (t ?t) (distance (nth$ 3 ?l)))))
      (case PLRS    then (assert (PLRS (run ?run) (t ?t))))
      (case PLRT    then (assert (PLRT (run ?run) (t ?t))))
      (case PLRB    then (assert (PLRB (run ?run) (t ?t))))
      (case PLRO    then (assert (PLRO (run ?run) (t ?t))))
      (case PLCN    then (assert (PLCN (run ?run) (t ?t))))
      (case PLCO    then (assert (PLCO (run ?run) (t ?t))))
      (case PLF     then (assert (PLF (run ?run) (t ?t) (reason (nth$ 3 ?l)))))
      (case SVRDY   then (assert (SVRDY (run ?run) (t ?t))))
      (case SVSTOP  then (assert (SVSTOP (run ?run) (t ?t) (reason (nth$ 3 ?l)))))
      (case TCTAKE  then (assert (TCTAKE (run ?run) (t ?t))))
      (case GPRS    then (assert (GPRS (run ?run) (t ?t))))
      (case GPRT    then (assert (GPRT (run ?run) (t ?t))))
      (case GPRB    then (assert (GPRB (run ?run) (t ?t))))
      (case GPCC    then (assert (GPCC (run ?run) (t ?t))))
      (case GPGL    then (assert (GPGL (run ?run) (t ?t) (remaining (nth$ 3 ?l)))))))

;;; ─── One event ──────────────────────────────────────────────────────────

;; ?l is the exploded line (T NAME V...), ?index its 0-based index.
(deffunction post (?index ?l)
   (bind ?t (nth$ 1 ?l))
   (bind ?e (nth$ 2 ?l))
   (bind ?i (member$ ?e ?*events*))
   (if (not ?i) then
      (printout t "ERROR: event " ?index ": unknown event " ?e crlf)
      (close)
      (exit 1))
   (bind ?k (nth$ ?i ?*event-agent*))
   ;; 1. now
   (if (> ?t ?*now*) then
      (bind ?*now* ?t)
      (bind ?*clock* (modify ?*clock* (now ?t))))
   ;; 2. expiry, then rest
   (if (and (> ?*now* ?*deadline*) (expire-agents)) then (to-rest ?index))
   ;; 3. the new fact replaces the old one, then rest
   (bind ?old (nth$ ?k ?*fact*))
   (bind ?run 1)
   (if ?old then
      (if (eq (fact-relation ?old) ?e) then
         (bind ?run (+ (fact-slot-value ?old run) 1)))
      (retract ?old))
   (if (<= ?k ?*n-stale*) then
      (bind ?m (nth$ ?k ?*stale*))
      (if ?m then
         (retract ?m)
         (bind ?*stale* (replace$ ?*stale* ?k ?k FALSE)))
      (if (not ?old) then
         (bind ?*deadline* (min ?*deadline* (+ ?t (nth$ ?k ?*stale-after*))))))
   (bind ?*fact* (replace$ ?*fact* ?k ?k (assert-event ?e ?run ?t ?l)))
   (to-rest ?index)
   ;; 4. the state sequence
   (if (neq ?*state* ?*prev*) then
      (printout states ?index " " ?*state* crlf)
      (bind ?*changes* (+ ?*changes* 1))
      (bind ?*prev* ?*state*)))

;;; ─── The stream ─────────────────────────────────────────────────────────

(deffunction main (?stream ?out)
   (if (not (open ?stream events "r")) then
      (printout t "ERROR: cannot read " ?stream crlf)
      (exit 1))
   (if (not (open ?out states "w")) then
      (printout t "ERROR: cannot write " ?out crlf)
      (exit 1))
   (set-reset-globals FALSE)   ; (reset) must keep the driver's globals
   (new-mission)
   (bind ?index 0)
   (bind ?start (time))
   (bind ?line (readline events))
   (while (neq ?line EOF)
      (if (neq (str-index "#" ?line) 1) then
         (bind ?l (explode$ ?line))
         (if (> (length$ ?l) 0) then
            ;; 0. a mission that ended at the previous event
            (if (or (eq ?*state* GL) (eq ?*state* SP)) then (new-mission))
            (post ?index ?l)
            (bind ?index (+ ?index 1))))
      (bind ?line (readline events)))
   (bind ?seconds (- (time) ?start))
   (close events)
   (close states)
   (printout t "RESULT " ?index " " ?seconds " " ?*changes* crlf))
