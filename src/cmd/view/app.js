// situ view: draws what /api/program, /api/graph and /api/timeline serve.
// A time is chosen with ?at=SECONDS or #t=SECONDS, a state's wiring with
// ?state=NAME, playing from that time with ?play; scrubbing and playing
// move both.
"use strict";

const view = { program: null, timeline: null, t: null, selected: null, follow: true, timer: null, lags: [] };

function $(id) { return document.getElementById(id); }
function el(tag, attrs, text) {
  const e = document.createElement(tag);
  for (const k in attrs || {}) e.setAttribute(k, attrs[k]);
  if (text !== undefined && text !== null) e.textContent = text;
  return e;
}
function seconds(ns) { return (ns / 1e9).toFixed(3) + " s"; }

async function get(path, asText) {
  const r = await fetch(path);
  if (!r.ok) throw new Error(path + ": HTTP " + r.status);
  return asText ? r.text() : r.json();
}

// The time asked for in the address, in nanoseconds (null: none).
function askedTime() {
  const q = new URLSearchParams(location.search).get("at");
  const h = /(?:^#|&)t=([0-9.]+)/.exec(location.hash);
  const s = h ? h[1] : q;
  const v = s === null ? NaN : parseFloat(s);
  return isFinite(v) && v >= 0 ? Math.round(v * 1e9) : null;
}

// The state, visited states, recorded modes and last firing at time t.
function at(t) {
  const p = view.program, tl = view.timeline;
  // A live run's log may start after the run did: from its base.
  const base = tl.base || {};
  const out = { state: base.state || p.initial, visited: (base.visited || []).slice(), modes: Object.assign({}, base.modes || {}), last: -1 };
  if (out.visited.indexOf(out.state) < 0) out.visited.unshift(out.state);
  if (!tl.recording) return out;
  tl.changes.forEach(function (c, i) {
    if (c.t <= t) {
      out.state = c.to;
      out.last = i;
      if (out.visited.indexOf(c.to) < 0) out.visited.push(c.to);
    }
  });
  tl.modes.forEach(function (m) { if (m.t <= t) out.modes[m.agent] = m; });
  return out;
}

function drawGraph(now) {
  document.querySelectorAll("#graph g.node").forEach(function (g) {
    const s = g.getAttribute("data-state");
    g.classList.toggle("current", s === now.state);
    g.classList.toggle("visited", s !== now.state && now.visited.indexOf(s) >= 0);
    g.classList.toggle("selected", s === view.selected);
  });
}

function drawWiring(now) {
  const p = view.program;
  const s = view.follow ? now.state : view.selected;
  view.selected = s;
  const si = p.states.findIndex(function (x) { return x.name === s; });
  $("wiring-state").textContent = s + (s === now.state ? " (current)" : "");
  $("wiring-description").textContent = (p.states[si] && p.states[si].description) || "";
  const body = $("wiring").querySelector("tbody");
  body.textContent = "";
  p.agents.forEach(function (a) {
    const w = a.states[si];
    let mode = w.mode, fn = w.function || "";
    const rec = s === now.state ? now.modes[a.name] : null;
    const tr = el("tr", { "data-agent": a.name });
    tr.appendChild(el("td", { title: a.description || "" }, a.name));
    tr.appendChild(el("td", {}, a.kind));
    if (rec) { mode = rec.mode; fn = rec.function || fn; }
    const m = el("td", { class: "mode mode-" + mode, "data-mode": mode }, mode);
    if (rec) m.appendChild(el("span", { class: "recorded" }, " (recorded)"));
    else if (w.by === "fsm") m.appendChild(el("span", { class: "recorded" }, " (fsm: initial)"));
    tr.appendChild(m);
    tr.appendChild(el("td", { class: "function" }, fn));
    tr.appendChild(el("td", {}, w.from.join(", ")));
    tr.appendChild(el("td", {}, w.to.join(", ")));
    body.appendChild(tr);
  });
}

function drawRules(now) {
  const tl = view.timeline;
  const fired = now.last >= 0 ? tl.changes[now.last].rules : [];
  document.querySelectorAll("#rules details.rule").forEach(function (d) {
    d.classList.toggle("fired", fired.indexOf(d.getAttribute("data-rule")) >= 0);
  });
}

function drawFirings(now) {
  document.querySelectorAll("#firings li.firing").forEach(function (li, i) {
    li.className = "firing " + (i < now.last ? "past" : i === now.last ? "now" : "future");
  });
  const t = view.t;
  document.querySelectorAll("#refused li").forEach(function (li) {
    li.hidden = Number(li.getAttribute("data-t")) > t;
  });
  const shown = document.querySelectorAll("#refused li:not([hidden])").length;
  $("refused-none").hidden = shown > 0;
}

function draw() {
  const t = view.t === null ? 0 : view.t;
  const now = at(t);
  $("current-state").textContent = now.state;
  document.body.setAttribute("data-current-state", now.state);
  $("current-time").textContent = view.timeline.recording ? "at " + seconds(t) : "(initial)";
  $("time-label").textContent = seconds(t) + " / " + seconds(view.timeline.end_ns || 0) + (view.timeline.live ? " (live)" : "");
  drawGraph(now);
  drawWiring(now);
  drawRules(now);
  if (view.timeline.recording) drawFirings(now);
}

function setTime(t, fromScrub) {
  view.t = Math.max(0, Math.min(t, view.timeline.end_ns || 0));
  if (!fromScrub) $("scrub").value = String(Math.round(view.t / 1e6));
  history.replaceState(null, "", "#t=" + (view.t / 1e9).toFixed(3));
  view.follow = true;
  draw();
}

function buildStatic() {
  const p = view.program;
  document.title = "situ view: " + p.name;
  $("title").textContent = p.name;
  $("kind").textContent = p.kind + " · " + p.states.length + " states, " + p.agents.length + " agents, " + p.rules.length + " rules";
  const rules = $("rules");
  p.rules.forEach(function (r) {
    const d = el("details", { class: "rule", "data-rule": r.name });
    d.appendChild(el("summary", {}, r.name + " → " + r.target + "  (salience " + r.salience + ", " + r.file + ":" + r.line + ")"));
    if (r.description) d.appendChild(el("p", {}, r.description));
    d.appendChild(el("pre", { class: "source" }, r.text));
    rules.appendChild(d);
  });
  document.querySelectorAll("#graph g.node").forEach(function (g) {
    g.addEventListener("click", function () {
      const s = g.getAttribute("data-state");
      if (!s) return;
      view.selected = s;
      view.follow = false;
      const now = at(view.t === null ? 0 : view.t);
      drawGraph(now);
      drawWiring(now);
    });
  });
}

function addFiring(c) {
  const li = el("li", { class: "firing", "data-t": String(c.t) });
  const a = el("a", { href: "#t=" + (c.t / 1e9).toFixed(3) }, seconds(c.t) + ": " + c.from + " → " + c.to + " by " + c.rules.join(", "));
  a.addEventListener("click", function (ev) { ev.preventDefault(); setTime(c.t); });
  li.appendChild(a);
  li.appendChild(el("pre", { class: "explain" }, c.explain));
  $("firings").appendChild(li);
}

// The first 500 refusals are listed, the rest counted.
function addRefused(r) {
  view.refusedSeen = (view.refusedSeen || 0) + 1;
  if (view.refusedSeen <= 500) {
    $("refused").appendChild(el("li", { "data-t": String(r.t) }, seconds(r.t) + ": " + r.agent + " " + r.event + " refused: " + r.reason));
  }
  $("refused-more").textContent = view.refusedSeen > 500 ? (view.refusedSeen - 500) + " more" : "";
}

// A live run (`situ run … --serve`): asks /api/live for what came after the
// entries it has, as soon as there is any; follows the run's latest time
// unless the person scrubbed back.
async function follow() {
  const tl = view.timeline;
  let since = 0;
  $("live").hidden = false;
  document.body.setAttribute("data-live", "running");
  for (;;) {
    let a;
    try {
      a = await get("/api/live?since=" + since);
    } catch (e) {
      $("live").textContent = "the run's server went away";
      document.body.setAttribute("data-live", "gone");
      return;
    }
    const atEnd = view.t >= tl.end_ns;
    if (a.reset) {
      tl.base = a.base;
      tl.changes = []; tl.modes = []; tl.refused = [];
      $("firings").textContent = ""; $("refused").textContent = "";
      view.refusedSeen = a.base.refused;
    }
    a.entries.forEach(function (e) {
      if (e.kind === "change") {
        tl.changes.push(e);
        addFiring(e);
      } else if (e.kind === "mode") {
        tl.modes.push(e);
      } else if (e.kind === "refused") {
        tl.refused.push(e);
        addRefused(e);
      }
    });
    tl.end_ns = Math.max(tl.end_ns, a.end_ns);
    $("scrub").max = String(Math.ceil(tl.end_ns / 1e6));
    view.received = (view.received || 0) + a.entries.length;
    document.body.setAttribute("data-received", String(view.received));
    if (atEnd) setTime(tl.end_ns); else draw();
    // How late each change was drawn after the server stamped it (ms, the
    // machine's clock; meaningless under a headless browser's virtual time).
    const drawn = Date.now() * 1000;
    a.entries.forEach(function (e) {
      if (e.kind === "change") view.lags.push((drawn - e.wall_us) / 1000);
    });
    since = a.next;
    if (a.over) {
      $("live").textContent = "the run is over: the page keeps what it was sent";
      document.body.setAttribute("data-live", "over");
      return;
    }
  }
}

function buildTimeline() {
  const tl = view.timeline;
  if (!tl.recording) return;
  $("timeline").hidden = false;
  $("firings-box").hidden = false;
  $("refused-box").hidden = false;
  if (tl.cut) $("cut").textContent = "cut short: " + tl.cut;
  const scrub = $("scrub");
  scrub.max = String(Math.ceil(tl.end_ns / 1e6));
  scrub.addEventListener("input", function () { setTime(Number(scrub.value) * 1e6, true); });
  tl.changes.forEach(addFiring);
  tl.refused.forEach(addRefused);
  $("play").addEventListener("click", function () {
    if (view.timer) {
      clearInterval(view.timer);
      view.timer = null;
      $("play").textContent = "▶ play";
      return;
    }
    if (view.t >= tl.end_ns) setTime(0);
    $("play").textContent = "❚❚ pause";
    // Ten times real time, 20 frames a second.
    view.timer = setInterval(function () {
      setTime(view.t + 0.5e9);
      if (view.t >= tl.end_ns) $("play").click();
    }, 50);
  });
}

async function main() {
  const got = await Promise.all([get("/api/program"), get("/api/graph", true), get("/api/timeline")]);
  view.program = got[0];
  view.timeline = got[2];
  $("graph").innerHTML = got[1];
  buildStatic();
  buildTimeline();
  const asked = new URLSearchParams(location.search).get("state");
  if (asked && view.program.states.some(function (s) { return s.name === asked; })) {
    view.selected = asked;
    view.follow = false;
  }
  const t = askedTime();
  view.t = view.timeline.recording ? (t === null ? 0 : Math.min(t, view.timeline.end_ns)) : 0;
  $("scrub").value = String(Math.round(view.t / 1e6));
  draw();
  window.addEventListener("hashchange", function () {
    const t = askedTime();
    if (t !== null && view.timeline.recording && Math.abs(t - view.t) > 1e6) setTime(t);
  });
  // ?play: plays from the time chosen (a link that shows a run as it went).
  if (view.timeline.recording && new URLSearchParams(location.search).has("play")) $("play").click();
  document.body.setAttribute("data-ready", "true");
  if (view.timeline.live) follow();
}

main();
