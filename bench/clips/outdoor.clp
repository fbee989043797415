;;; ═══════════════════════════════════════════════════════════════════════
;;;  outdoor.clp: the situation rules of rules/outdoor.situ in CLIPS 6.30.
;;;
;;;  The working memory of docs/language.md 10.2, one fact per thing:
;;;
;;;   (system (state S))    the current system state (initially IT);
;;;   (clock (now N))       now, in ns: the largest timestamp seen; the
;;;                         driver modifies it when an event advances it, so
;;;                         that `within` windows are re-tested (see below);
;;;   (LAOBS (run R) (t T) (distance D) (height H)) ...
;;;                         each agent's latest event, as a fact of the
;;;                         event's template (one template per event, with
;;;                         the event's payload fields as slots); an agent
;;;                         has at most one such fact, kept by the driver;
;;;   (stale LADAR)         the agent's fact has expired (`stale LADAR`).
;;;
;;;  Each situ rule is one defrule with the same name and salience:
;;;   - state guard:      ?sys <- (system (state ?s&RS|RT|RB)), then
;;;                       (test (neq ?s TARGET)): a rule is activated only
;;;                       when its target differs from the current state;
;;;   - E(f < v) xN:      (E (f ?x&:(< ?x v)) (run ?r&:(>= ?r N)));
;;;   - not P:            (not (E ...));
;;;   - stale A:          (stale A);
;;;   - within 500ms:     (E (t ?t1)) ... (clock (now ?now))
;;;                       (test (<= (- ?now ?t1) 500000000)).
;;;
;;;  Why the clock fact comes last: CLIPS evaluates a join test only when a
;;;  partial match enters the join, never because time passed. With the
;;;  clock pattern as the last positive CE and the window test after it,
;;;  every change of any matched fact, of the state, or of now re-enters the
;;;  last join, so a window is always tested against the current now. The
;;;  clock's join memory is almost always empty (its left side needs every
;;;  other condition of the rule to hold), so advancing now costs little.
;;;
;;;  Conflict resolution: situ orders activations by salience, specificity,
;;;  recency, declaration order; CLIPS here by salience, then its default
;;;  depth strategy. In outdoor.situ two rules of one salience that can be
;;;  activated together always have the same target (header of its rules
;;;  section, docs/language.md 10.5), so the next state and the whole
;;;  cascade are the same whichever of them fires.
;;;
;;;  The driver (driver.clp) posts the events and brings the network to
;;;  rest; every rule's action is (goto ?sys TARGET RULE).
;;; ═══════════════════════════════════════════════════════════════════════

(deftemplate system (slot state (type SYMBOL) (default IT)))
(deftemplate clock (slot now (type INTEGER) (default 0)))

;;; ─── Events: one template per event, in the agents' declaration order ───
;;; Every fact has its run length `run` and timestamp `t` (ns), then the
;;; payload fields in the order the event declares them.

;; RFCCD (stale after 400ms)
(deftemplate RFRS (slot run) (slot t))
(deftemplate RFRT (slot run) (slot t) (slot curvature (type FLOAT)) (slot side (allowed-symbols left right)))
(deftemplate RFRB (slot run) (slot t) (slot distance (type FLOAT)))
(deftemplate RFRN (slot run) (slot t))
;; STCCD (stale after 500ms)
(deftemplate STOBS (slot run) (slot t) (slot distance (type FLOAT)) (slot width (type FLOAT)))
(deftemplate STOBN (slot run) (slot t))
;; LADAR (stale after 300ms)
(deftemplate LAOBS (slot run) (slot t) (slot distance (type FLOAT)) (slot height (type FLOAT)))
(deftemplate LAOBN (slot run) (slot t))
;; Localization (stale after 200ms)
(deftemplate LOFIX (slot run) (slot t) (slot error (type FLOAT)))
(deftemplate LOLOST (slot run) (slot t))
;; Fusion
(deftemplate FURS (slot run) (slot t))
(deftemplate FURT (slot run) (slot t))
(deftemplate FURB (slot run) (slot t))
(deftemplate FURO (slot run) (slot t) (slot distance (type FLOAT)))
(deftemplate FUCN (slot run) (slot t))
(deftemplate FUCO (slot run) (slot t) (slot distance (type FLOAT)))
;; GPL
(deftemplate GPRS (slot run) (slot t))
(deftemplate GPRT (slot run) (slot t))
(deftemplate GPRB (slot run) (slot t))
(deftemplate GPCC (slot run) (slot t))
(deftemplate GPGL (slot run) (slot t) (slot remaining (type FLOAT)))
;; LPL
(deftemplate PLRS (slot run) (slot t))
(deftemplate PLRT (slot run) (slot t))
(deftemplate PLRB (slot run) (slot t))
(deftemplate PLRO (slot run) (slot t))
(deftemplate PLCN (slot run) (slot t))
(deftemplate PLCO (slot run) (slot t))
(deftemplate PLF (slot run) (slot t) (slot reason (allowed-symbols no_path blocked timeout)))
;; Drive
(deftemplate DRSTOP (slot run) (slot t))
(deftemplate DRFAULT (slot run) (slot t) (slot code (type INTEGER)))
;; Supervisor
(deftemplate SVRDY (slot run) (slot t))
(deftemplate SVSTOP (slot run) (slot t) (slot reason (allowed-symbols operator stuck danger)))
;; TeleControl (stale after 1s)
(deftemplate TCHB (slot run) (slot t))
(deftemplate TCTAKE (slot run) (slot t))

;;; ─── Firing ─────────────────────────────────────────────────────────────

(defglobal
   ?*state* = IT        ; the current state (kept in step with the system fact)
   ?*firings* = 0       ; firings in the current rest (the driver resets it)
   ?*fired* = (create$) ; "rule>STATE" of the current rest, for the error message
)

;; The action of every rule: set the state to the rule's target.
(deffunction goto (?sys ?target ?rule)
   (bind ?*firings* (+ ?*firings* 1))
   (if (<= ?*firings* 65) then
      (bind ?*fired* (create$ ?*fired* (sym-cat ?rule ">" ?target))))
   (bind ?*state* ?target)
   (modify ?sys (state ?target)))

;;; ═══════════════════════════════════════════════════════════════════════
;;;  Situation rules (same names, saliences and order as outdoor.situ)
;;; ═══════════════════════════════════════════════════════════════════════

;;; ─── 100: emergency ─────────────────────────────────────────────────────

;; rule planner_failed salience 100 "LPL cannot plan" { when state not in {EM, GL, SP} and PLF then EM }
(defrule planner_failed (declare (salience 100))
   ?sys <- (system (state ?s&~EM&~GL&~SP))
   (test (neq ?s EM))
   (PLF)
   =>
   (goto ?sys EM planner_failed))

;; rule drive_fault salience 100 "not under control" { when state not in {EM, GL, SP} and DRFAULT then EM }
(defrule drive_fault (declare (salience 100))
   ?sys <- (system (state ?s&~EM&~GL&~SP))
   (test (neq ?s EM))
   (DRFAULT)
   =>
   (goto ?sys EM drive_fault))

;; rule collision_imminent salience 100 {
;;     when state in {RS, RT, RB, RO, CN, CO} and LAOBS(distance < 5.0, height > 0.15) then EM }
(defrule collision_imminent (declare (salience 100))
   ?sys <- (system (state ?s&RS|RT|RB|RO|CN|CO))
   (test (neq ?s EM))
   (LAOBS (distance ?d&:(< ?d 5.0)) (height ?h&:(> ?h 0.15)))
   =>
   (goto ?sys EM collision_imminent))

;; rule localization_lost salience 100 { when state in {RS, RT, RB, RO, CN, CO} and LOLOST then EM }
(defrule localization_lost (declare (salience 100))
   ?sys <- (system (state ?s&RS|RT|RB|RO|CN|CO))
   (test (neq ?s EM))
   (LOLOST)
   =>
   (goto ?sys EM localization_lost))

;; rule localization_silent salience 100 {
;;     when state in {RS, RT, RB, RO, CN, CO} and stale Localization then EM }
(defrule localization_silent (declare (salience 100))
   ?sys <- (system (state ?s&RS|RT|RB|RO|CN|CO))
   (test (neq ?s EM))
   (stale Localization)
   =>
   (goto ?sys EM localization_silent))

;; rule ladar_silent salience 100 { when state in {RS, RT, RB, RO, CN, CO} and stale LADAR then EM }
(defrule ladar_silent (declare (salience 100))
   ?sys <- (system (state ?s&RS|RT|RB|RO|CN|CO))
   (test (neq ?s EM))
   (stale LADAR)
   =>
   (goto ?sys EM ladar_silent))

;; rule road_camera_silent salience 100 { when state in {RS, RT, RB, RO} and stale RFCCD then EM }
(defrule road_camera_silent (declare (salience 100))
   ?sys <- (system (state ?s&RS|RT|RB|RO))
   (test (neq ?s EM))
   (stale RFCCD)
   =>
   (goto ?sys EM road_camera_silent))

;; rule stereo_silent salience 100 { when state in {CN, CO} and stale STCCD then EM }
(defrule stereo_silent (declare (salience 100))
   ?sys <- (system (state ?s&CN|CO))
   (test (neq ?s EM))
   (stale STCCD)
   =>
   (goto ?sys EM stereo_silent))

;; rule safety_radio_lost salience 100 "no operator heartbeat for 1 s" {
;;     when state in {RS, RT, RB, RO, CN, CO} and stale TeleControl then EM }
(defrule safety_radio_lost (declare (salience 100))
   ?sys <- (system (state ?s&RS|RT|RB|RO|CN|CO))
   (test (neq ?s EM))
   (stale TeleControl)
   =>
   (goto ?sys EM safety_radio_lost))

;;; ─── 90: stop (which also ends an emergency) ────────────────────────────

;; rule operator_takes_over salience 90 { when state not in {GL, SP} and TCTAKE then SP }
(defrule operator_takes_over (declare (salience 90))
   ?sys <- (system (state ?s&~GL&~SP))
   (test (neq ?s SP))
   (TCTAKE)
   =>
   (goto ?sys SP operator_takes_over))

;; rule supervisor_stop salience 90 { when state not in {GL, SP} and SVSTOP then SP }
(defrule supervisor_stop (declare (salience 90))
   ?sys <- (system (state ?s&~GL&~SP))
   (test (neq ?s SP))
   (SVSTOP)
   =>
   (goto ?sys SP supervisor_stop))

;; rule emergency_halted salience 90 { when state == EM and DRSTOP within 100ms then SP }
(defrule emergency_halted (declare (salience 90))
   ?sys <- (system (state ?s&EM))
   (test (neq ?s SP))
   (DRSTOP (t ?t1))
   (clock (now ?now))
   (test (<= (- ?now ?t1) 100000000))
   =>
   (goto ?sys SP emergency_halted))

;;; ─── 80: goal ───────────────────────────────────────────────────────────

;; rule goal_reached salience 80 { when state in {RS, RT, RB, RO, CN, CO} and GPGL(remaining < 2.0) then GL }
(defrule goal_reached (declare (salience 80))
   ?sys <- (system (state ?s&RS|RT|RB|RO|CN|CO))
   (test (neq ?s GL))
   (GPGL (remaining ?m&:(< ?m 2.0)))
   =>
   (goto ?sys GL goal_reached))

;;; ─── 60: readiness lost ─────────────────────────────────────────────────

;; rule readiness_lost salience 60 { when state == RD and LOLOST then IT }
(defrule readiness_lost (declare (salience 60))
   ?sys <- (system (state ?s&RD))
   (test (neq ?s IT))
   (LOLOST)
   =>
   (goto ?sys IT readiness_lost))

;;; ─── 50: an obstacle is seen ────────────────────────────────────────────

;; rule road_obstacle_ladar salience 50 {
;;     when state in {RS, RT, RB} and LAOBS(distance < 30.0, height > 0.15) then RO }
(defrule road_obstacle_ladar (declare (salience 50))
   ?sys <- (system (state ?s&RS|RT|RB))
   (test (neq ?s RO))
   (LAOBS (distance ?d&:(< ?d 30.0)) (height ?h&:(> ?h 0.15)))
   =>
   (goto ?sys RO road_obstacle_ladar))

;; rule road_obstacle_stereo salience 50 { when state in {RS, RT, RB} and STOBS(distance < 30.0) then RO }
(defrule road_obstacle_stereo (declare (salience 50))
   ?sys <- (system (state ?s&RS|RT|RB))
   (test (neq ?s RO))
   (STOBS (distance ?d&:(< ?d 30.0)))
   =>
   (goto ?sys RO road_obstacle_stereo))

;; rule terrain_obstacle_ladar salience 50 { when state == CN and LAOBS(distance < 20.0, height > 0.3) then CO }
(defrule terrain_obstacle_ladar (declare (salience 50))
   ?sys <- (system (state ?s&CN))
   (test (neq ?s CO))
   (LAOBS (distance ?d&:(< ?d 20.0)) (height ?h&:(> ?h 0.3)))
   =>
   (goto ?sys CO terrain_obstacle_ladar))

;; rule terrain_obstacle_stereo salience 50 { when state == CN and STOBS(distance < 20.0) then CO }
(defrule terrain_obstacle_stereo (declare (salience 50))
   ?sys <- (system (state ?s&CN))
   (test (neq ?s CO))
   (STOBS (distance ?d&:(< ?d 20.0)))
   =>
   (goto ?sys CO terrain_obstacle_stereo))

;;; ─── 40: an obstacle is passed ──────────────────────────────────────────

;; rule obstacle_passed_straight salience 40 {
;;     when state == RO and FURS within 500ms and PLRS within 500ms and LAOBN x3
;;      and not STOBS(distance < 30.0)
;;     then RS }
(defrule obstacle_passed_straight (declare (salience 40))
   ?sys <- (system (state ?s&RO))
   (test (neq ?s RS))
   (FURS (t ?t1))
   (PLRS (t ?t2))
   (LAOBN (run ?r&:(>= ?r 3)))
   (not (STOBS (distance ?d&:(< ?d 30.0))))
   (clock (now ?now))
   (test (and (<= (- ?now ?t1) 500000000) (<= (- ?now ?t2) 500000000)))
   =>
   (goto ?sys RS obstacle_passed_straight))

;; rule obstacle_passed_in_turn salience 40 {
;;     when state == RO and FURT within 500ms and PLRT within 500ms and LAOBN x3
;;      and not STOBS(distance < 30.0)
;;     then RT }
(defrule obstacle_passed_in_turn (declare (salience 40))
   ?sys <- (system (state ?s&RO))
   (test (neq ?s RT))
   (FURT (t ?t1))
   (PLRT (t ?t2))
   (LAOBN (run ?r&:(>= ?r 3)))
   (not (STOBS (distance ?d&:(< ?d 30.0))))
   (clock (now ?now))
   (test (and (<= (- ?now ?t1) 500000000) (<= (- ?now ?t2) 500000000)))
   =>
   (goto ?sys RT obstacle_passed_in_turn))

;; rule obstacle_passed_at_branch salience 40 {
;;     when state == RO and FURB within 500ms and PLRB within 500ms and LAOBN x3
;;      and not STOBS(distance < 30.0)
;;     then RB }
(defrule obstacle_passed_at_branch (declare (salience 40))
   ?sys <- (system (state ?s&RO))
   (test (neq ?s RB))
   (FURB (t ?t1))
   (PLRB (t ?t2))
   (LAOBN (run ?r&:(>= ?r 3)))
   (not (STOBS (distance ?d&:(< ?d 30.0))))
   (clock (now ?now))
   (test (and (<= (- ?now ?t1) 500000000) (<= (- ?now ?t2) 500000000)))
   =>
   (goto ?sys RB obstacle_passed_at_branch))

;; rule road_obstacle_off_road salience 40 "the way around leaves the road" {
;;     when state == RO and FUCO within 500ms and PLCO within 500ms then CO }
(defrule road_obstacle_off_road (declare (salience 40))
   ?sys <- (system (state ?s&RO))
   (test (neq ?s CO))
   (FUCO (t ?t1))
   (PLCO (t ?t2))
   (clock (now ?now))
   (test (and (<= (- ?now ?t1) 500000000) (<= (- ?now ?t2) 500000000)))
   =>
   (goto ?sys CO road_obstacle_off_road))

;; rule terrain_obstacle_passed salience 40 {
;;     when state == CO and FUCN within 500ms and PLCN within 500ms and LAOBN x3 and STOBN then CN }
(defrule terrain_obstacle_passed (declare (salience 40))
   ?sys <- (system (state ?s&CO))
   (test (neq ?s CN))
   (FUCN (t ?t1))
   (PLCN (t ?t2))
   (LAOBN (run ?r&:(>= ?r 3)))
   (STOBN)
   (clock (now ?now))
   (test (and (<= (- ?now ?t1) 500000000) (<= (- ?now ?t2) 500000000)))
   =>
   (goto ?sys CN terrain_obstacle_passed))

;; rule terrain_obstacle_onto_road salience 40 "the way around joins a road" {
;;     when state == CO and FURO within 500ms and PLRO within 500ms then RO }
(defrule terrain_obstacle_onto_road (declare (salience 40))
   ?sys <- (system (state ?s&CO))
   (test (neq ?s RO))
   (FURO (t ?t1))
   (PLRO (t ?t2))
   (clock (now ?now))
   (test (and (<= (- ?now ?t1) 500000000) (<= (- ?now ?t2) 500000000)))
   =>
   (goto ?sys RO terrain_obstacle_onto_road))

;;; ─── 30: mission flow ───────────────────────────────────────────────────

;; rule initialized salience 30 { when state == IT and SVRDY and TCHB and LOFIX(error < 0.5) x10 then RD }
(defrule initialized (declare (salience 30))
   ?sys <- (system (state ?s&IT))
   (test (neq ?s RD))
   (SVRDY)
   (TCHB)
   (LOFIX (error ?e&:(< ?e 0.5)) (run ?r&:(>= ?r 10)))
   =>
   (goto ?sys RD initialized))

;; rule start_on_road salience 30 { when state == RD and GPRS and RFRS x3 and LAOBN x3 and STOBN then RS }
(defrule start_on_road (declare (salience 30))
   ?sys <- (system (state ?s&RD))
   (test (neq ?s RS))
   (GPRS)
   (RFRS (run ?r1&:(>= ?r1 3)))
   (LAOBN (run ?r2&:(>= ?r2 3)))
   (STOBN)
   =>
   (goto ?sys RS start_on_road))

;; rule start_in_turn salience 30 { when state == RD and GPRT and RFRT x3 and LAOBN x3 and STOBN then RT }
(defrule start_in_turn (declare (salience 30))
   ?sys <- (system (state ?s&RD))
   (test (neq ?s RT))
   (GPRT)
   (RFRT (run ?r1&:(>= ?r1 3)))
   (LAOBN (run ?r2&:(>= ?r2 3)))
   (STOBN)
   =>
   (goto ?sys RT start_in_turn))

;; rule start_cross_country salience 30 { when state == RD and GPCC and LAOBN x3 and STOBN x3 then CN }
(defrule start_cross_country (declare (salience 30))
   ?sys <- (system (state ?s&RD))
   (test (neq ?s CN))
   (GPCC)
   (LAOBN (run ?r1&:(>= ?r1 3)))
   (STOBN (run ?r2&:(>= ?r2 3)))
   =>
   (goto ?sys CN start_cross_country))

;;; ─── 30: road geometry ──────────────────────────────────────────────────

;; rule road_straight salience 30 { when state in {RT, RB} and RFRS x3 then RS }
(defrule road_straight (declare (salience 30))
   ?sys <- (system (state ?s&RT|RB))
   (test (neq ?s RS))
   (RFRS (run ?r&:(>= ?r 3)))
   =>
   (goto ?sys RS road_straight))

;; rule road_turn salience 30 { when state in {RS, RB} and RFRT(curvature >= 0.02) x2 then RT }
(defrule road_turn (declare (salience 30))
   ?sys <- (system (state ?s&RS|RB))
   (test (neq ?s RT))
   (RFRT (curvature ?c&:(>= ?c 0.02)) (run ?r&:(>= ?r 2)))
   =>
   (goto ?sys RT road_turn))

;; rule road_branch salience 30 { when state in {RS, RT} and RFRB and GPRB then RB }
(defrule road_branch (declare (salience 30))
   ?sys <- (system (state ?s&RS|RT))
   (test (neq ?s RB))
   (RFRB)
   (GPRB)
   =>
   (goto ?sys RB road_branch))

;; rule road_ends salience 30 { when state in {RS, RT, RB} and GPCC and RFRN x3 then CN }
(defrule road_ends (declare (salience 30))
   ?sys <- (system (state ?s&RS|RT|RB))
   (test (neq ?s CN))
   (GPCC)
   (RFRN (run ?r&:(>= ?r 3)))
   =>
   (goto ?sys CN road_ends))

;; rule back_on_road salience 30 { when state == CN and GPRS and RFRS x3 then RS }
(defrule back_on_road (declare (salience 30))
   ?sys <- (system (state ?s&CN))
   (test (neq ?s RS))
   (GPRS)
   (RFRS (run ?r&:(>= ?r 3)))
   =>
   (goto ?sys RS back_on_road))
