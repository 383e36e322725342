// pressplan serve: the page. Every number comes from the server, which calls the same functions as the CLI.
"use strict";

const SESSION = (crypto.randomUUID ? crypto.randomUUID() : String(Math.random()).slice(2)) ;
const SECTIONS = ["press", "press.link_drive", "press.knuckle_joint", "key_points", "process", "robots", "robots.unloader", "robots.loader", "limits", "drive", "drive.motor", "planner"];
// with robots the one-height model's two fields are left out (the robots replace them; the case refuses both)
const ONE_HEIGHT_KEYS = ["process.safety_height_mm", "process.transfer_time_s"];
// the press section's own keys belong to the crank-slider; a linkage's dimensions are in its subsection
const CRANK_SLIDER_KEYS = ["press.crank_radius_mm", "press.rod_length_mm", "press.offset_mm", "drive.rod_mass_kg", "drive.rod_cg_from_crank_pin_mm"];
const SECTION_TITLES = { robots: "robots", "robots.unloader": "unloader (takes the part out)", "robots.loader": "loader (brings the blank in)", press: "press", "press.link_drive": "link drive", "press.knuckle_joint": "knuckle joint", key_points: "key angles", process: "process", limits: "limits", drive: "drive", "drive.motor": "motor (all motors together)", planner: "planner" };
const WINDOW_COLOUR = "#d9ecff", DRAW_COLOUR = "#e2f0d9", HOLD_COLOUR = "#c8b99a"; // the robot's window, the draw, a hold
const KEY_LABELS = { closing: "θ1", draw_start: "θ2", draw_end: "θ3", opening: "θ4", closing_back: "θ1′", draw_start_back: "θ2′", draw_end_back: "θ3′", opening_back: "θ4′" };
const TYPING_REST_MS = 120; // a pause this long in typing solves (a fast typist's keys come closer)
const BOUND_REST_MS = 800;

const state = { meta: null, label: "case", data: null, seq: 0, shownSeq: -1, last: null, pinned: null };
// how a solve ended: the server's one outcome type (planning.model.outcome), sent with /api/meta; the
// page compares an answer's status against these, never against text of its own
let OUTCOME = { ERROR: "error" };

function $(sel) { return document.querySelector(sel); }

function getPath(obj, dotted) {
  return dotted.split(".").reduce((o, k) => (o == null ? undefined : o[k]), obj);
}

function setPath(obj, dotted, value) {
  const keys = dotted.split(".");
  let node = obj;
  for (const k of keys.slice(0, -1)) { if (node[k] == null) node[k] = {}; node = node[k]; }
  const leaf = keys[keys.length - 1];
  if (value === undefined) delete node[leaf]; else node[leaf] = value;
}

// ---- the form ---------------------------------------------------------------------------------------
function buildForm(data) {
  const form = $("#case-form");
  form.innerHTML = "";
  const specs = state.meta.fields;
  const hasDrive = data.drive != null, hasRobots = data.robots != null;
  const crankSlider = (getPath(data, "press.mechanism") || "crank-slider") === "crank-slider";
  for (const section of SECTIONS) {
    if (section === "drive" && !hasDrive) { form.appendChild(addDriveBox()); continue; }
    if (section === "robots" && !hasRobots) { form.appendChild(addRobotsBox()); continue; }
    if (section.startsWith("drive") && !hasDrive) continue;
    if (section.includes(".") && !section.startsWith("drive") && getPath(data, section) == null) continue;
    const fields = specs.filter((f) => f.name.startsWith(section + ".") && !f.name.slice(section.length + 1).includes("."))
      .filter((f) => crankSlider || !CRANK_SLIDER_KEYS.includes(f.name))
      .filter((f) => !hasRobots || !ONE_HEIGHT_KEYS.includes(f.name));
    if (!fields.length) continue;
    const fs = document.createElement("fieldset");
    fs.dataset.section = section;
    fs.innerHTML = `<legend>${SECTION_TITLES[section] || section}</legend>`;
    for (const spec of fields) fs.appendChild(spec.kind === "table" ? forceTable(spec, getPath(data, spec.name)) : fieldRow(spec, getPath(data, spec.name)));
    if (section === "drive") {
      fs.appendChild(button({ id: "remove-drive" }, "remove the drive", "plan the motion alone (no motor limits, no torque or energy)", removeDrive));
    }
    if (section === "robots") {
      fs.appendChild(button({ id: "remove-robots" }, "remove the robots", "back to one safety height and one transfer time (the template press's)", removeRobots));
      for (const name of ROBOT_NAMES) { // a robot left out is added back from the template
        if (data.robots[name] == null) fs.appendChild(button({ id: `add-${name}` }, `add the ${name}`, `the ${name} of the template press (pressplan new --robots)`, () => addRobot(name)));
      }
    }
    if (section.startsWith("robots.")) {
      const name = section.slice("robots.".length), other = ROBOT_NAMES.find((n) => n !== name);
      if (data.robots[other] != null) fs.appendChild(button({ id: `remove-${name}` }, `remove the ${name}`, `the press without its ${name} (the other robot stays)`, () => removeRobot(name)));
    }
    form.appendChild(fs);
  }
  const general = document.createElement("div");
  general.className = "field";
  general.innerHTML = `<span class="msg" data-for=""></span>`;
  form.appendChild(general);
}

// a button of the form: ``props`` (id or className), its text, its tooltip, what a click does
function button(props, text, title, onClick) {
  const b = Object.assign(document.createElement("button"), { type: "button", textContent: text, title, ...props });
  b.addEventListener("click", onClick);
  return b;
}

// a drive added in the page: the drive of `pressplan new`'s template press of this mechanism (and its
// forming force, when the case has none), to be replaced by the press's own figures
function addDriveBox() {
  const fs = document.createElement("fieldset");
  fs.dataset.section = "drive";
  fs.innerHTML = `<legend>drive</legend><p class="help-text">No drive: the plan keeps the motion's limits only. ` +
    `A drive adds the motor's torque, RMS and speed limits, the energy, and the objectives at the line's rate.</p>`;
  fs.appendChild(button({ id: "add-drive" }, "add a drive", "starts from the drive of a template press of this mechanism (pressplan new --drive): enter your press's figures", addDrive));
  return fs;
}

function addDrive() {
  const data = caseFromForm();
  const kind = getPath(data, "press.mechanism") || "crank-slider";
  const template = structuredClone(state.meta.drive_templates[kind]);
  data.drive = template.drive;
  if (data.process.forming_force_kN == null) data.process.forming_force_kN = template.forming_force_kN;
  state.data = data;
  buildForm(data);
  setStatus("a drive added: the template press's figures; enter your press's", "busy");
  solveNow();
}

function removeDrive() {
  const data = caseFromForm();
  delete data.drive;
  if (data.planner && data.planner.objective && data.planner.objective !== "max-spm") data.planner.objective = "max-spm"; // the objectives weigh the motor
  state.data = data;
  buildForm(data);
  solveNow();
}

// robots added in the page: an unloader and a loader of `pressplan new --robots`'s template press of this
// mechanism (their tools needing the safety height over the die), to be replaced by the line's own figures
function addRobotsBox() {
  const fs = document.createElement("fieldset");
  fs.dataset.section = "robots";
  fs.innerHTML = `<legend>robots</legend><p class="help-text">One safety height and one transfer time. Robots on their ` +
    `interference curves plan the unloader and the loader with the slide: they go in while it is still rising.</p>`;
  fs.appendChild(button({ id: "add-robots" }, "add robots", "an unloader and a loader of a template press of this mechanism (pressplan new --robots): enter your robots' figures", addRobots));
  return fs;
}

function addRobots() {
  const data = caseFromForm();
  const kind = getPath(data, "press.mechanism") || "crank-slider";
  data.robots = structuredClone(state.meta.robot_templates[kind].robots);
  for (const key of ONE_HEIGHT_KEYS) setPath(data, key, undefined);
  state.data = data;
  buildForm(data);
  setStatus("robots added: the template press's; enter your robots' figures", "busy");
  solveNow();
}

const ROBOT_NAMES = ["unloader", "loader"];

function addRobot(name) {
  const data = caseFromForm();
  const kind = getPath(data, "press.mechanism") || "crank-slider";
  data.robots[name] = structuredClone(state.meta.robot_templates[kind].robots[name]);
  state.data = data;
  buildForm(data);
  solveNow();
}

function removeRobot(name) {
  const data = caseFromForm();
  delete data.robots[name];
  state.data = data;
  buildForm(data);
  solveNow();
}

function removeRobots() {
  const data = caseFromForm();
  const kind = getPath(data, "press.mechanism") || "crank-slider";
  delete data.robots;
  const oneHeight = state.meta.robot_templates[kind].one_height;
  for (const [key, value] of Object.entries(oneHeight)) setPath(data, "process." + key, value);
  state.data = data;
  buildForm(data);
  solveNow();
}

// a table of number pairs (the forming force's height and force, an interference curve's position and
// height), rows added and removed in place
function forceTable(spec, value) {
  const row = document.createElement("div");
  row.className = "field table-field";
  const id = "f-" + spec.name.replaceAll(".", "-");
  row.innerHTML = `<label title="${spec.name}: ${spec.help}">${spec.title}</label><small class="help">${spec.help}</small>`;
  const table = document.createElement("table");
  table.className = "force-table";
  table.id = id;
  table.dataset.field = spec.name;
  table.dataset.kind = "table";
  const [first, second] = spec.columns || ["height mm", "force kN"];
  table.innerHTML = `<thead><tr><th>${first}</th><th>${second}</th><th></th></tr></thead><tbody></tbody>`;
  const body = table.querySelector("tbody");
  const addRow = (pair) => {
    const tr = document.createElement("tr");
    for (let k = 0; k < 2; k++) {
      const cell = document.createElement("input");
      cell.type = "text";
      cell.inputMode = "decimal";
      cell.className = "cell";
      cell.value = pair && pair[k] != null ? String(pair[k]) : "";
      cell.addEventListener("change", onEdit);
      cell.addEventListener("input", typed);
      const td = document.createElement("td");
      td.appendChild(cell);
      tr.appendChild(td);
    }
    const drop = button({ className: "drop-row" }, "×", "remove this row", () => { tr.remove(); onEdit(); });
    const td = document.createElement("td");
    td.appendChild(drop);
    tr.appendChild(td);
    body.appendChild(tr);
  };
  for (const pair of value || []) addRow(pair);
  row.appendChild(table);
  row.appendChild(button({ className: "add-row" }, "add a row", "", () => { addRow(null); body.lastChild.querySelector("input").focus(); }));
  const msg = document.createElement("span");
  msg.className = "msg";
  msg.dataset.for = spec.name;
  const warn = document.createElement("span");
  warn.className = "warn";
  warn.dataset.warnFor = spec.name;
  row.appendChild(msg);
  row.appendChild(warn);
  return row;
}

function typed() {
  window.lastInputAt = performance.now(); // the typing benchmark reads it
  clearTimeout(editTimer);
  editTimer = setTimeout(onEdit, TYPING_REST_MS);
  setStatus("editing… the plan follows when the typing pauses", "busy"); // pending from the first key
}

function fieldRow(spec, value) {
  const row = document.createElement("div");
  row.className = "field";
  const id = "f-" + spec.name.replaceAll(".", "-");
  let input;
  if (spec.kind === "label") {
    input = document.createElement("input");
    input.type = "text";
    input.readOnly = true;
    input.value = value ?? "";
  } else if (spec.kind === "choice") {
    input = document.createElement("select");
    for (const c of spec.choices) {
      const option = new Option(c, c);
      // an objective at the line's rate weighs the motor: not offered on a case without a drive
      if (spec.name === "planner.objective" && c !== "max-spm" && !(state.data && state.data.drive)) {
        option.disabled = true;
        option.title = "needs a drive: section (the motor it weighs)";
      }
      input.add(option);
    }
    input.value = value ?? spec.choices[0];
  } else {
    input = document.createElement("input");
    input.type = "text";
    input.inputMode = "decimal";
    input.value = value == null ? "" : String(value);
    if (spec.optional) input.placeholder = "none";
  }
  input.id = id;
  input.dataset.field = spec.name;
  input.dataset.kind = spec.kind;
  row.innerHTML = `<label for="${id}" title="${spec.name}: ${spec.help}">${spec.title}</label>`;
  input.title = `${spec.name}: ${spec.help}`;
  row.appendChild(input);
  const help = document.createElement("small");
  help.className = "help";
  help.textContent = spec.help;
  row.appendChild(help);
  const msg = document.createElement("span");
  msg.className = "msg";
  msg.dataset.for = spec.name;
  const warn = document.createElement("span");
  warn.className = "warn";
  warn.dataset.warnFor = spec.name;
  row.appendChild(msg);
  row.appendChild(warn);
  if (spec.kind !== "label") input.addEventListener("change", onEdit);
  if (spec.kind !== "choice" && spec.kind !== "label") input.addEventListener("input", typed); // typing: solve once the keys rest (a change solves at once)
  return row;
}

function formValue(input) {
  if (input.dataset.kind === "table") { // rows of numbers; a row left blank is no row; no rows: omitted
    const rows = [...input.querySelectorAll("tbody tr")].map((tr) => [...tr.querySelectorAll("input")].map((c) => c.value.trim()))
      .filter((pair) => pair.some((v) => v !== "")).map((pair) => pair.map(numberOf));
    return rows.length ? rows : undefined;
  }
  const text = input.value.trim();
  if (input.dataset.kind === "choice" || input.dataset.kind === "label") return text || undefined;
  if (text === "") return undefined;
  return numberOf(text);
}

// a number as typed, or the text itself (the server then says what is wrong with it); a decimal comma, as
// many locales write it, is a decimal point ("1,8" is 1.8; a comma with a point as well is left to the server)
function numberOf(text) {
  if (/^[-+]?[1-9]\d{0,2},\d{3}$/.test(text)) return text; // "1,200": a thousands separator or a decimal comma? the server refuses it
  const typed = /^[-+]?\d*,\d+([eE][-+]?\d+)?$/.test(text) ? text.replace(",", ".") : text;
  const number = Number(typed);
  return Number.isFinite(number) && /^[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$/.test(typed) ? number : text;
}

function caseFromForm() {
  const data = structuredClone(state.data);
  for (const input of document.querySelectorAll("#case-form [data-field]")) setPath(data, input.dataset.field, formValue(input));
  return data;
}

// ---- solving ----------------------------------------------------------------------------------------
let editTimer = null;
function onEdit() {
  clearTimeout(editTimer);
  // a change event that changes nothing (the field left after its edit was solved) solves nothing
  if (state.solvedJson !== undefined && JSON.stringify(caseFromForm()) === state.solvedJson) {
    if (state.statusLine) setStatus(...state.statusLine); // typed back to the case solved: its status again
    return;
  }
  solveNow();
}

// every answer of the server is JSON (errors too); anything else (a proxy's page, a dropped connection)
// becomes an error answer the page shows, never an exception
async function readJson(responsePromise) {
  let response;
  try {
    response = await responsePromise;
  } catch (e) {
    return { status: OUTCOME.ERROR, message: "the server did not answer: " + e, confirmed: true };
  }
  try {
    return await response.json();
  } catch (e) {
    return { status: OUTCOME.ERROR, message: `the server answered ${response.status} without JSON`, confirmed: true };
  }
}

async function post(url, body) {
  const response = await fetch(url, { method: "POST", headers: { "Content-Type": "application/json" }, body: JSON.stringify(body) });
  return response;
}

async function askSolve(data, seq, confirm) {
  return readJson(post("/api/solve", { session: SESSION, seq, label: state.label, case: data, confirm }));
}

async function solveNow() {
  const data = caseFromForm();
  state.solvedJson = JSON.stringify(data);
  remember(state.solvedJson);
  const seq = ++state.seq;
  setStatus("solving…", "busy");
  document.body.dataset.state = "solving";
  window.solveSentAt = performance.now();
  // first the fast answer from the plan on screen, then (when it was not the cold solve's) the confirmed
  // one: the cold solve's plan or better, whatever the order of the edits
  let answer = await askSolve(data, seq, false);
  window.solveAnsweredAt = performance.now();
  if (answer.status === OUTCOME.INTERRUPTED || seq < state.seq) return; // a newer edit is on its way
  if (answer.status === OUTCOME.VERIFIED && !answer.confirmed) {
    state.data = data;
    render(answer, seq, false);
    answer = await askSolve(data, seq, true);
    if (answer.status === OUTCOME.INTERRUPTED || seq < state.seq) return;
  }
  clearMessages();
  showWarnings(answer.warnings || []);
  if (answer.status === OUTCOME.VERIFIED) {
    state.data = data;
    render(answer, seq, true);
    // the bound (half a second, in the server's other process) once the edits rest
    setTimeout(() => { if (seq === state.shownSeq) requestBound(data, seq); }, BOUND_REST_MS);
  } else {
    if (state.newCase) clearPlan(); // a case just loaded that has no plan: show none, not the last case's
    // keep the last good plan of this case on screen; say what is wrong, next to the field when one is named
    const field = answer.field || "";
    showMessage(field, answer.message);
    showBadge(answer.message);
    setStatus(answer.message + (field && answer.status !== OUTCOME.BAD_INPUT ? ` (the limit: ${field})` : ""), "failed");
    document.body.dataset.state = answer.status;
    document.body.dataset.rendered = String(seq);
  }
}

function clearPlan() {
  state.last = null;
  for (const id of ["#spm", "#cycle", "#binding", "#bound-share"]) $(id).textContent = "–";
  for (const id of ["#drive-line", "#objective-line", "#pin-line", "#summary"]) $(id).textContent = "";
  $("#key-points tbody").innerHTML = "";
  $("#stages tbody").innerHTML = "";
  Plotly.purge("motion-chart");
  for (const id of ["robots-chart", "drive-chart", "energy-chart"]) { Plotly.purge(id); $("#" + id).style.display = "none"; }
  $("#mechanism-svg").innerHTML = "";
  $("#utilisation").innerHTML = "";
  showBadge("no plan");
}

async function requestBound(data, seq) {
  const answer = await readJson(post("/api/bound", { label: state.label, case: data }));
  if (seq !== state.shownSeq || !state.last) return; // another plan, or none, on screen since it was asked
  const spm = state.last.result.spm;
  // the share of the certified upper bound (no motion within the limits makes more: never above 100 %)
  const bounded = answer.upper_spm != null; // else the answer says why there is no bound
  $("#bound-share").textContent = bounded ? (100 * spm / answer.upper_spm).toFixed(1) + " %" : "no bound";
  $("#bound-share").title = bounded
    ? `bracket: ${spm.toFixed(3)} strokes/min verified … ${answer.upper_spm.toFixed(3)} certified upper bound (no motion within the limits makes more` +
      (answer.left_out.length ? `; left out: ${answer.left_out.join(", ")}` : "") + ")" +
      (answer.spm != null ? `; the grid bound ${answer.spm.toFixed(3)}` : "")
    : answer.message;
}

// valid entries that look unintended (planning.model.plausibility): beside their fields, never refusals
function showWarnings(warnings) {
  for (const el of document.querySelectorAll(".warn[data-warn-for]")) el.textContent = "";
  for (const w of warnings) {
    const el = document.querySelector(`.warn[data-warn-for="${CSS.escape(w.field)}"]`);
    if (el) el.textContent = "⚠ " + w.message;
  }
}

// which plan is on screen: the live one, or the last good one while the form's case has none (``refused``)
function showBadge(refused) {
  const badge = $("#plan-badge");
  const r = state.last ? state.last.result : null;
  const stale = Boolean(refused);
  document.body.dataset.stale = stale && r ? "1" : "";
  if (stale && state.camFile) camReset(); // a proved cam belongs to the plan, not to the form's refused case
  const swing = Boolean(r && r.mode === "pendulum"); // a pendulum's files: pressplan solve and cam write them
  for (const b of document.querySelectorAll("#downloads button, #cam-prove")) {
    b.disabled = stale || swing;
    b.title = stale ? "the case on the form has no plan: fix the value marked, then download"
      : swing ? "a pendulum stroke's files and cams: pressplan solve and pressplan cam write them (not the page yet)" : "";
  }
  if (!r) { badge.textContent = refused ? "no plan" : ""; badge.className = "badge none"; return; }
  const what = `${r.motion_law}, ${planWords(r)}, ${r.spm.toFixed(3)} strokes/min`;
  if (stale) {
    badge.textContent = `showing the last good plan (${what}): the case on the form has none`;
    badge.className = "badge stale";
  } else {
    const confirmed = document.body.dataset.state !== "confirming";
    badge.textContent = `live plan: ${what}, ` + (confirmed ? "confirmed" : "fast answer, confirming…");
    badge.className = "badge " + (confirmed ? "live" : "busy");
  }
}

function clearMessages() {
  for (const el of document.querySelectorAll(".msg[data-for]")) el.textContent = "";
  for (const el of document.querySelectorAll("#case-form .bad")) el.classList.remove("bad");
}

function showMessage(field, message) {
  // the field's own message place, or its table's (``process.forming_force_kN.2.1``: row 3, force)
  const parts = field.split(".");
  let name = field, rest = [];
  while (parts.length && !document.querySelector(`.msg[data-for="${CSS.escape(parts.join("."))}"]`)) rest.unshift(parts.pop());
  if (parts.length) name = parts.join(".");
  let target = document.querySelector(`.msg[data-for="${CSS.escape(name)}"]`);
  if (!target || !field) target = document.querySelector('.msg[data-for=""]');
  target.textContent = message;
  const input = field ? document.querySelector(`[data-field="${CSS.escape(name)}"]`) : null;
  if (!input) return;
  input.classList.add("bad");
  if (input.dataset.kind === "table" && rest.length) {
    const filled = [...input.querySelectorAll("tbody tr")].filter((tr) => [...tr.querySelectorAll("input")].some((c) => c.value.trim() !== ""));
    const row = filled[Number(rest[0])]; // the rows sent: the blank ones are left out
    const cells = row ? row.querySelectorAll("input") : [];
    for (const [k, cell] of [...cells].entries()) if (rest.length < 2 || Number(rest[1]) === k) cell.classList.add("bad");
  }
}

function setStatus(text, kind) {
  if (!text.startsWith("editing…")) state.statusLine = [text, kind]; // what an edit that changed nothing restores
  const el = $("#status");
  el.textContent = text;
  el.className = "status " + (kind || "");
}

// ---- rendering --------------------------------------------------------------------------------------
// what drawCharts and drawMechanism read of an answer: its curves, its limits' lines, its strokes, its key points
function chartsOf(answer) {
  return [answer.curves, answer.limit_lines, answer.result.spm, answer.result.key_points];
}

// two answers' chart data the same to far below a pixel: numbers within SAME_CHART of the larger (or of 1), the rest
// equal (the cold solve's plan and a neighbour's start's same optimum differ in their last digits)
const SAME_CHART = 1e-9;
function sameCharts(a, b) {
  if (typeof a === "number" && typeof b === "number") return Math.abs(a - b) <= SAME_CHART * Math.max(1, Math.abs(a), Math.abs(b));
  if (Array.isArray(a) && Array.isArray(b)) return a.length === b.length && a.every((x, i) => sameCharts(x, b[i]));
  if (a && b && typeof a === "object" && typeof b === "object") {
    const keys = Object.keys(a);
    return keys.length === Object.keys(b).length && keys.every((k) => k in b && sameCharts(a[k], b[k]));
  }
  return a === b;
}

function render(answer, seq, confirmed) {
  // the confirmed answer of an edit whose fast answer is on screen with the same charts: not drawn again
  const drawn = state.last && seq === state.shownSeq && sameCharts(chartsOf(state.last), chartsOf(answer));
  if (state.meta.cam && seq !== state.shownSeq) camReset(); // the cam proved was of another plan
  if (seq !== state.shownSeq) { $("#bound-share").textContent = "…"; $("#bound-share").title = "the bound follows once the edits rest"; } // never the last plan's bracket
  state.last = answer;
  state.shownSeq = seq;
  state.newCase = false;
  $("#summary").textContent = answer.summary || "";
  const r = answer.result;
  $("#spm").textContent = r.spm.toFixed(3);
  $("#cycle").textContent = r.cycle_time_s.toFixed(4);
  $("#binding").textContent = r.binding_constraints.join(", ") || "none";
  setStatus(`${r.motion_law}, ${planWords(r)}, ${r.status}: every limit holds on the dense ${(r.verification.step_s * 1e3).toFixed(3)} ms grid` +
    (confirmed ? "" : "; confirming against the cold solve…"), confirmed ? "" : "busy");
  $("#objective-line").textContent = r.baseline
    ? `${r.objective} at ${r.target_spm} SPM: RMS ${(r.drive.rms_motor_torque_Nm / 1e3).toFixed(2)} kN m, energy ${r.energy_kJ.toFixed(1)} kJ/stroke (${r.energy_at === "bus" ? "at the bus" : "at the shaft"}); ` +
      `saving ${r.saving_pct.rms_torque.toFixed(1)} % RMS, ${r.saving_pct.energy.toFixed(1)} % energy` +
      (r.saving_pct.grid_peak !== undefined ? `, ${r.saving_pct.grid_peak.toFixed(1)} % grid peak (${r.baseline.grid_peak_kW.toFixed(0)} → ${r.power.grid_peak_kW.toFixed(0)} kW)` : "") +
      " against waiting"
    : "";
  $("#drive-line").textContent = r.drive
    ? `motor: peak ${(r.drive.peak_motor_torque_Nm / 1e3).toFixed(2)} kN m (${r.drive.peak_torque_use_pct.toFixed(1)} % of the envelope), ` +
      `RMS ${(r.drive.rms_motor_torque_Nm / 1e3).toFixed(2)} kN m (${r.drive.rms_torque_use_pct.toFixed(1)} % of rated), ` +
      `peak power ${r.drive.peak_motor_power_kW.toFixed(0)} kW, ${r.drive.energy_drawn_kJ.toFixed(1)} kJ drawn per stroke`
    : "";
  showPin();
  const body = $("#key-points tbody");
  body.innerHTML = "";
  for (const k of r.key_points) {
    const tr = document.createElement("tr");
    tr.innerHTML = `<td>${k.name}</td><td>${k.angle_deg.toFixed(2)}</td><td>${k.time_s.toFixed(4)}</td><td>${k.height_mm.toFixed(1)}</td>` +
      `<td>${k.slider_speed_mm_s.toFixed(1)} ${k.direction}</td><td>${k.crank_speed_rpm.toFixed(3)}</td>`;
    body.appendChild(tr);
  }
  const stages = $("#stages tbody");
  stages.innerHTML = "";
  for (const st of r.stages || []) {
    const tr = document.createElement("tr");
    tr.innerHTML = `<td>${st.name}</td><td>${st.start_angle_deg.toFixed(2)}</td><td>${st.end_angle_deg.toFixed(2)}</td>` +
      `<td>${st.start_time_s.toFixed(4)}</td><td>${st.duration_s.toFixed(4)}</td><td>${st.peak_crank_speed_rpm.toFixed(3)}</td><td class="binds">${st.binding.join(", ") || "–"}</td>`;
    stages.appendChild(tr);
  }
  if ((r.binding_over_cycle || []).length) {
    const tr = document.createElement("tr");
    tr.innerHTML = `<td>the cycle</td><td colspan="5"></td><td class="binds">${r.binding_over_cycle.join(", ")}</td>`;
    stages.appendChild(tr);
  }
  drawUtilisation(answer.utilisation || []);
  document.body.dataset.state = confirmed ? "ready" : "confirming";
  showBadge(null); // before the charts: the chart takes the room the lines above it leave
  showWarnings(answer.warnings || []);
  if (!drawn) {
    drawCharts();
    drawMechanism();
  }
  // the edit-to-chart benchmark reads them: the first chart of an edit, and the confirmed one
  if (!confirmed || window.firstRenderedSeq !== seq) { window.firstRenderedAt = performance.now(); window.firstRenderedSeq = seq; }
  window.renderedAt = performance.now();
  document.body.dataset.rendered = String(seq);
}

// how the plan runs, in words: its placement, or a pendulum stroke's swings
function planWords(r) {
  return r.mode === "pendulum" ? "pendulum strokes" : `${r.placement} placement`;
}

// the pinned plan's SPM beside the one on screen (a pin changes nothing else: the badge and status stay)
function showPin() {
  const r = state.last.result, p = state.pinned;
  $("#pin-line").textContent = p
    ? `pinned ${p.result.spm.toFixed(3)} SPM: difference ${(r.spm - p.result.spm >= 0 ? "+" : "")}${(r.spm - p.result.spm).toFixed(3)} SPM`
    : "";
}

// each limit's use by the plan as a bar, in the case's order of limits; the binding ones marked
function drawUtilisation(rows) {
  const box = $("#utilisation");
  box.innerHTML = "";
  for (const row of rows) {
    const line = document.createElement("div");
    line.className = row.binds ? "binds" : "";
    line.dataset.limit = row.field || row.id;
    const pct = Math.min(row.pct, 100);
    line.innerHTML = `<span class="name"></span><span class="bar"><span style="width:${pct.toFixed(1)}%"></span></span><span class="pct">${row.pct.toFixed(row.pct >= 99.95 ? 0 : 1)} %</span>`;
    const name = line.querySelector(".name");
    name.textContent = row.name;
    name.title = `${row.field || row.id}: ${row.pct.toFixed(3)} % of the limit` + (row.binds ? " (binds)" : "");
    box.appendChild(line);
  }
}

// ---- undo and redo: the cases sent to the server, in order (a case loaded starts a new history) ---------
const HISTORY_LENGTH = 50;
const history = { cases: [], at: -1, moving: false };

function remember(json) {
  if (history.moving) { history.moving = false; return; } // an undo or redo solves a case already in the list
  if (history.cases[history.at] === json) return;
  history.cases = history.cases.slice(0, history.at + 1);
  history.cases.push(json);
  if (history.cases.length > HISTORY_LENGTH) history.cases.shift();
  history.at = history.cases.length - 1;
  historyButtons();
}

function forgetHistory() {
  history.cases = [];
  history.at = -1;
  historyButtons();
}

function historyButtons() {
  $("#undo").disabled = history.at <= 0;
  $("#redo").disabled = history.at >= history.cases.length - 1;
}

function moveInHistory(step) {
  const at = history.at + step;
  if (at < 0 || at >= history.cases.length) return;
  clearTimeout(editTimer);
  history.at = at;
  history.moving = true;
  historyButtons();
  state.data = JSON.parse(history.cases[at]);
  buildForm(state.data);
  solveNow();
}

// ---- recipes: cases kept under a name in the server's recipes folder (serve --recipes DIR) -------------
async function listRecipes(selected) {
  const answer = await readJson(fetch("/api/recipes"));
  const select = $("#recipe-select");
  select.innerHTML = "";
  select.add(new Option(answer.names && answer.names.length ? "open…" : "none saved", ""));
  for (const name of answer.names || []) select.add(new Option(name, name));
  select.value = selected || "";
}

async function saveRecipe() {
  const name = $("#recipe-name").value.trim();
  const answer = await readJson(post("/api/recipes", { name, label: state.label, case: caseFromForm() }));
  if (answer.saved == null) { $("#load-message").textContent = answer.message; return; }
  $("#load-message").textContent = `saved as recipe ${answer.saved}`;
  await listRecipes(answer.saved);
}

async function openRecipe(name) {
  if (!name) return;
  const mine = ++loads;
  const answer = await readJson(fetch("/api/recipe/" + encodeURIComponent(name)));
  if (mine !== loads) return;
  showLoaded(answer);
  if (answer.case != null) { $("#recipe-name").value = name; $("#case-select").selectedIndex = -1; }
}

function xOf(curves) {
  return $("#x-axis").value === "time" ? curves.time_s : curves.crank_angle_deg;
}

// the robot's window theta4 -> TDC -> theta1 and the draw theta2 -> theta3 shaded, the key points dotted,
// the window's time written on it (the figures of `pressplan solve` show the same)
// the motion chart's panels, one quantity each (its own axis, its zero where the data crosses it); the user
// picks which (the page fits a laptop's screen with the default four)
const PANELS = [
  { key: "slider_height_mm", title: "slide height [mm]", color: "#1f77b4", on: true },
  { key: "crank_speed_rpm", title: "crank speed [rpm]", color: "#d62728", on: true },
  { key: "crank_accel_rad_s2", title: "crank accel [rad/s²]", color: "#9467bd", on: false },
  { key: "crank_jerk_rad_s3", title: "crank jerk [rad/s³]", color: "#8c564b", on: false },
  { key: "slider_speed_mm_s", title: "slide speed [mm/s]", color: "#2ca02c", on: true },
  { key: "slider_accel_mm_s2", title: "slide accel [mm/s²]", color: "#ff7f0e", on: true },
];
const TRACE_NAMES = { slider_height_mm: "slide height [mm]", crank_speed_rpm: "crank speed [rpm]", crank_accel_rad_s2: "crank acceleration [rad/s²]", crank_jerk_rad_s3: "crank jerk [rad/s³]", slider_speed_mm_s: "slide speed [mm/s]", slider_accel_mm_s2: "slide acceleration [mm/s²]" };
const OFF_SCALE = 3; // a limit beyond this many times the curve's own extent is written, not drawn to scale
const LABEL_PX = 6.5; // about a chart label's character width [px], to leave out a label where it would not fit

function buildPanels() {
  const box = $("#panels");
  for (const panel of PANELS) {
    const label = document.createElement("label");
    label.innerHTML = `<input type="checkbox" data-panel="${panel.key}"${panel.on ? " checked" : ""}> ${panel.title.split(" [")[0]}`;
    box.appendChild(label);
  }
  box.addEventListener("change", () => { if (state.last) drawCharts(); });
}

function pickedPanels() {
  return PANELS.filter((p) => document.querySelector(`[data-panel="${p.key}"]`).checked);
}

function cycleShapes(r, x, axis, width) {
  if (r.windows) return swingShapes(r, axis);
  const at = (name) => { const k = r.key_points.find((p) => p.name === name); return axis === "time" ? k.time_s : k.angle_deg; };
  const rect = (x0, x1, fillcolor) => ({ type: "rect", xref: "x", yref: "paper", x0, x1, y0: 0, y1: 1, fillcolor, opacity: 0.6, line: { width: 0 }, layer: "below" });
  const robots = r.robots != null; // the robots' interference curves replace the one robot's window
  const shapes = robots ? [rect(at("draw_start"), at("draw_end"), DRAW_COLOUR)] : [rect(at("opening"), x[x.length - 1], WINDOW_COLOUR), rect(x[0], at("closing"), WINDOW_COLOUR), rect(at("draw_start"), at("draw_end"), DRAW_COLOUR)];
  for (const k of r.key_points) {
    const kx = axis === "time" ? k.time_s : k.angle_deg;
    shapes.push({ type: "line", xref: "x", yref: "paper", x0: kx, x1: kx, y0: 0, y1: 1, line: { dash: "dot", width: 1, color: "#555" } });
  }
  // the window's and the draw's names, each inside its own shading, left out where it would not fit
  const span = x[x.length - 1] - x[0], px = (a, b) => (Math.abs(b - a) / span) * width;
  const window = `robot window θ4 → θ1: ${r.transfer_window_s.toFixed(3)} s (≥ ${r.process.transfer_time_s} s)`;
  const before = px(x[0], at("closing")), after = px(at("opening"), x[x.length - 1]);
  const draw = "draw θ2 → θ3";
  const annotations = [];
  const windowText = window.length * LABEL_PX < Math.max(before, after) ? window : `window ${r.transfer_window_s.toFixed(3)} s`;
  if (!robots) annotations.push(before >= after
    ? { xref: "x", yref: "paper", x: x[0], y: 1.0, xanchor: "left", yanchor: "bottom", text: windowText, showarrow: false, font: { size: 11, color: "#1f4e79" } }
    : { xref: "x", yref: "paper", x: x[x.length - 1], y: 1.0, xanchor: "right", yanchor: "bottom", text: windowText, showarrow: false, font: { size: 11, color: "#1f4e79" } });
  if (draw.length * LABEL_PX < px(at("draw_start"), at("draw_end")) + 20) {
    annotations.push({ xref: "x", yref: "paper", x: (at("draw_start") + at("draw_end")) / 2, y: 1.0, xanchor: "center", yanchor: "bottom", text: draw, showarrow: false, font: { size: 11, color: "#3b6e22" } });
  }
  if (r.hold) holdShape(r.hold, at("draw_end"), axis, shapes, annotations);
  return { shapes, annotations };
}

// a pendulum stroke: the robot's windows through both turns and both swings' draws shaded, every key point a line
function swingShapes(r, axis) {
  const rect = ([x0, x1], fillcolor) => ({ type: "rect", xref: "x", yref: "paper", x0, x1, y0: 0, y1: 1, fillcolor, opacity: 0.6, line: { width: 0 }, layer: "below" });
  const shapes = [...r.windows[axis].map((span) => rect(span, WINDOW_COLOUR)), ...r.draws[axis].map((span) => rect(span, DRAW_COLOUR))];
  for (const k of r.key_points) {
    const kx = axis === "time" ? k.time_s : k.angle_deg;
    shapes.push({ type: "line", xref: "x", yref: "paper", x0: kx, x1: kx, y0: 0, y1: 1, line: { dash: "dot", width: 1, color: "#555" } });
  }
  const text = `robot windows through the turns: ${r.transfer_window_s.toFixed(3)} s (≥ ${r.process.transfer_time_s} s)`;
  const annotations = [{ xref: "paper", yref: "paper", x: 0, y: 1.0, xanchor: "left", yanchor: "bottom", text, showarrow: false, font: { size: 11, color: "#1f4e79" } }];
  return { shapes, annotations };
}

// a hold at the bottom: its standstill shaded against time (from the brake's end), a line at its angle
function holdShape(hold, drawEnd, axis, shapes, annotations) {
  const text = `hold ${hold.time_s} s`;
  if (axis === "time") {
    const x0 = drawEnd + hold.brake_s, x1 = x0 + hold.time_s;
    shapes.push({ type: "rect", xref: "x", yref: "paper", x0, x1, y0: 0, y1: 1, fillcolor: HOLD_COLOUR, opacity: 0.35, line: { width: 0 }, layer: "below" });
    annotations.push({ xref: "x", yref: "paper", x: (x0 + x1) / 2, y: 0.0, xanchor: "center", yanchor: "bottom", text, showarrow: false, font: { size: 11, color: "#6b5a3e" } });
  } else {
    shapes.push({ type: "line", xref: "x", yref: "paper", x0: hold.angle_deg, x1: hold.angle_deg, y0: 0, y1: 1, line: { width: 2, color: HOLD_COLOUR } });
    annotations.push({ xref: "x", yref: "paper", x: hold.angle_deg, y: 0.0, xanchor: "left", yanchor: "bottom", text, showarrow: false, font: { size: 11, color: "#6b5a3e" } });
  }
}

// each limit of the case on the panel of the quantity it bounds, dashed where it applies (the server's
// `limit_lines`, the figures' own), named by its case field; a limit far off the curve's scale is written on
// the panel instead of squashing the curve
function limitTraces(lines, x, axis, axes) {
  const traces = [];
  for (const line of lines || []) {
    const yaxis = axes[line.quantity];
    if (!yaxis) continue; // its panel is not shown
    const style = { dash: "dash", width: 1.2, color: line.colour };
    const common = { yaxis, name: line.label, legendgroup: line.field, hoverinfo: "name" };
    if (line.point) {
      const px = axis === "time" ? line.at.time : line.at.angle;
      traces.push({ ...common, x: [px, px], y: [line.upper[0], line.lower ? line.lower[0] : line.upper[0]], mode: "markers", marker: { symbol: "line-ew-open", size: 16, color: style.color, line: { width: 3 } } });
      continue;
    }
    traces.push({ ...common, x, y: line.upper, mode: "lines", line: style, connectgaps: false });
    if (line.lower) traces.push({ ...common, x, y: line.lower, mode: "lines", line: style, connectgaps: false, showlegend: false });
  }
  return traces;
}

function extent(values) {
  let lo = Infinity, hi = -Infinity;
  for (const v of values) if (v != null && Number.isFinite(v)) { if (v < lo) lo = v; if (v > hi) hi = v; }
  return [lo, hi];
}

// a panel's range: its curve's, with the limits that lie within OFF_SCALE of its extent; the others named
function panelRange(values, lines) {
  let [lo, hi] = extent(values);
  const size = Math.max(hi - lo, Math.abs(hi), Math.abs(lo), 1e-9);
  const off = [];
  for (const line of lines) {
    const [llo, lhi] = extent([...(line.upper || []), ...(line.lower || [])]);
    if (!Number.isFinite(llo)) continue;
    if (Math.max(Math.abs(llo), Math.abs(lhi)) > OFF_SCALE * size) { off.push(line); continue; }
    lo = Math.min(lo, llo); hi = Math.max(hi, lhi);
  }
  if (lo > 0 && lo < 0.25 * hi) lo = 0; // a positive curve near zero: from zero
  const pad = 0.08 * Math.max(hi - lo, 1e-9);
  return { range: [lo - pad, hi + pad], off };
}

// a short panel's ticks: the curve's own extremes (two digits) and zero, where auto ticks would leave only zero
// or crowd; a tall one's: plotly's, about one per 40 px
function panelTicks(values, range, panelPx) {
  if (panelPx >= 140) return { nticks: Math.floor(panelPx / 40) };
  const [lo, hi] = extent(values);
  const ticks = range[0] <= 0 && range[1] >= 0 ? [0] : [];
  const apart = 0.25 * (range[1] - range[0]); // a tick this close to another would print over it
  for (const v of [Number(lo.toPrecision(2)), Number(hi.toPrecision(2))]) {
    if (v >= range[0] && v <= range[1] && ticks.every((t) => Math.abs(t - v) >= apart)) ticks.push(v);
  }
  return { tickmode: "array", tickvals: ticks.sort((a, b) => a - b) };
}

const PANEL_PX = 80; // the least height of a panel [px]: its ticks and its name legible
function chartHeight(panels) {
  const panel = $("#result-panel"), chart = $("#motion-chart");
  const top = chart.getBoundingClientRect().top - panel.getBoundingClientRect().top + panel.scrollTop;
  const room = panel.clientHeight - top - 8;
  return Math.max(260, PANEL_PX * panels + 60, Math.min(room, 900));
}

function drawCharts() {
  window.chartDraws = (window.chartDraws || 0) + 1; // read by a test: a confirmed answer with the same charts is not drawn again
  const ans = state.last;
  const r = ans.result, c = ans.curves, axis = $("#x-axis").value;
  const x = xOf(c);
  const picked = pickedPanels();
  const chart = $("#motion-chart");
  const chartPx = chartHeight(picked.length);
  chart.style.height = chartPx + "px";
  const width = Math.max(200, chart.clientWidth - 62);
  const layout = {
    height: chartPx, // given, so that a redraw takes the box's new size (plotly keeps its first otherwise)
    margin: { l: 48, r: 14, t: 20, b: 40 },
    hovermode: "x unified",
    showlegend: false,
    xaxis: { title: { text: axis === "time" ? (r.windows ? "time from the forward swing's start [s]" : "time from TDC [s]") : "crank angle from TDC [deg]" }, anchor: `y${picked.length > 1 ? picked.length : ""}` },
  };
  const axes = {}, traces = [], gap = 0.04, n = Math.max(picked.length, 1), height = (1 - gap * (n - 1)) / n;
  const notes = [];
  picked.forEach((panel, i) => {
    const name = i === 0 ? "y" : `y${i + 1}`, key = i === 0 ? "yaxis" : `yaxis${i + 1}`;
    axes[panel.key] = name;
    const top = 1 - i * (height + gap);
    const lines = (ans.limit_lines || []).filter((l) => l.quantity === panel.key && !l.point);
    const { range, off } = panelRange(c[panel.key], lines);
    if (panel.key === "slider_height_mm") range[1] += 0.18 * (range[1] - range[0]); // room for the key angles' names
    // the panel's name inside it, top left (an axis title would not fit a short panel's height)
    const panelPx = height * (chartPx - 60);
    layout[key] = { ...ROUND_TICKS, ...panelTicks(c[panel.key], range, panelPx), domain: [top - height, top], range, zeroline: true, zerolinecolor: "#888" };
    notes.push({ xref: "paper", yref: "paper", x: 0, y: top, xanchor: "left", yanchor: "top", showarrow: false, text: panel.title, font: { size: 10, color: panel.color }, bgcolor: "rgba(255,255,255,0.75)" });
    traces.push({ x, y: c[panel.key], name: TRACE_NAMES[panel.key], yaxis: name, line: { color: panel.color } });
    if (off.length) notes.push({ xref: "paper", yref: "paper", x: 1, y: top, xanchor: "right", yanchor: "top", showarrow: false, font: { size: 10, color: "#7a4b00" }, text: off.map((l) => `${l.field} ${extent([...(l.upper || [])])[1].toPrecision(4)} off scale`).join("; ") });
    if (state.pinned) traces.push({ x: xOf(state.pinned.curves), y: state.pinned.curves[panel.key], name: "pinned " + TRACE_NAMES[panel.key], yaxis: name, line: { dash: "dot", color: "#777", width: 1 } });
  });
  traces.push(...limitTraces(ans.limit_lines, x, axis, axes));
  if (axes.slider_height_mm) {
    const keyX = r.key_points.map((k) => (axis === "time" ? k.time_s : k.angle_deg));
    const keyIndex = keyX.map((v) => nearest(x, v));
    traces.push({ x: keyX, y: keyIndex.map((i) => c.slider_height_mm[i]), text: r.key_points.map((k) => KEY_LABELS[k.name]), mode: "markers+text", textposition: "top center", cliponaxis: false, yaxis: axes.slider_height_mm, name: "key points", marker: { color: "#000", size: 7 }, showlegend: false });
  }
  const { shapes, annotations } = cycleShapes(r, x, axis, width);
  layout.shapes = shapes;
  layout.annotations = [...annotations, ...notes];
  Plotly.react("motion-chart", traces, layout, { responsive: true, displaylogo: false });
  if (!chart.dataset.follows) { chart.on("plotly_hover", followChart); chart.dataset.follows = "1"; }
  drawRobots(r, c, x, axis);
  drawDrive(r, c, x, axis);
  drawEnergy(r, c, x, axis);
}

// the interference chart (`pressplan solve`'s interference.png): the slide's height against the height each
// tool needs where it is over the die, the least clearance marked; below, each robot's position on its path
const ROBOT_COLOURS = { unloader: "#d62728", loader: "#2ca02c" };
function drawRobots(r, c, x, axis) {
  const el = $("#robots-chart");
  if (!r.robots) { Plotly.purge(el); el.style.display = "none"; return; }
  el.style.display = "block";
  const traces = [{ x, y: c.slider_height_mm, name: "slide height [mm]", line: { color: "#1f77b4" } }];
  const paths = [];
  for (const robot of r.robots.robots) {  // (a pendulum cycle's: each robot once in each window)
    const colour = ROBOT_COLOURS[robot.name] || "#000";
    if (!paths.some((p) => p.name.startsWith(`${robot.name} on`))) {
      const need = c[`${robot.name}_needed_height_mm`];
      // drawn where it needs height and one sample either side (the line reaches 0 where the tool leaves)
      const shown = need.map((v, i) => (v > 0 || need[i - 1] > 0 || need[i + 1] > 0 ? v : null));
      traces.push({ x, y: shown, name: `height the ${robot.name}'s tool needs [mm]`, line: { color: colour }, connectgaps: false });
      paths.push({ x, y: c[`${robot.name}_position_mm`], yaxis: "y2", name: `${robot.name} on its path [mm from the die centre]`, line: { color: colour, dash: "dot" } });
    }
    if (robot.least_clearance_mm != null) {
      const at = axis === "time" ? robot.least_clearance_time_s : c.crank_angle_deg[nearest(c.time_s, robot.least_clearance_time_s)];
      const clearance = (Math.round(robot.least_clearance_mm * 100) / 100 + 0).toFixed(2);
      const which = robot.window ? `${robot.name} ${robot.window}` : robot.name;
      traces.push({ x: [at], y: [robot.needed_there_mm], mode: "markers", marker: { symbol: "triangle-down", size: 10, color: colour }, name: `${which}: least clearance ${clearance} mm` });
    }
  }
  traces.push(...paths);
  const layout = {
    ...cycleChartLayout(r, x, axis, -0.18),
    title: { text: `robots on their interference curves (${r.robots.order})`, font: { size: 12 }, x: 0.01, xanchor: "left" },
    margin: { l: 60, r: 30, t: 30, b: 40 },
    xaxis: { title: { text: xAxisTitle(axis) }, anchor: "y2" },
    yaxis: { ...ROUND_TICKS, domain: [0.45, 1], rangemode: "tozero", title: { text: "height [mm]" } },
    yaxis2: { ...ROUND_TICKS, domain: [0, 0.38], rangemode: "tozero", title: { text: "path [mm]" } },
  };
  Plotly.react(el, traces, layout, { responsive: true, displaylogo: false });
}

function nearest(xs, v) {
  let best = 0;
  for (let i = 1; i < xs.length; i++) if (Math.abs(xs[i] - v) < Math.abs(xs[best] - v)) best = i;
  return best;
}

// the drive's and the energy chart's common layout: margins, the legend below, the stages shaded (x axis "x")
const ROUND_TICKS = { nticks: 6, tickformat: "~g" };
function xAxisTitle(axis) { return axis === "time" ? "time from TDC [s]" : "crank angle [deg]"; }
function cycleChartLayout(r, x, axis, legendY) {
  const { shapes } = cycleShapes(r, x, axis);
  return {
    margin: { l: 60, r: 30, t: 10, b: 40 },
    hovermode: "closest",
    legend: { orientation: "h", y: legendY, yanchor: "top", font: { size: 10 } },
    shapes: shapes.map((sh) => ({ ...sh, xref: "x", yref: "paper" })),
  };
}

function drawDrive(r, c, x, axis) {
  const el = $("#drive-chart");
  if (!r.drive || !c.motor_torque_Nm) { Plotly.purge(el); el.style.display = "none"; return; }
  el.style.display = "block";
  const m = r.drive.motor;
  const torque = c.motor_torque_Nm.map((v) => v / 1e3);
  // the envelope over the motor's speeds, both ways when it turns backward (a pendulum's backward swing)
  const forward = [0, m.base_speed_rpm];
  for (let k = 1; k <= 20; k++) forward.push(m.base_speed_rpm + (k / 20) * (m.max_speed_rpm - m.base_speed_rpm));
  const backward = c.motor_speed_rpm.some((n) => n < 0);
  const speeds = backward ? forward.slice(1).reverse().map((n) => -n).concat(forward) : forward;
  const envelope = speeds.map((n) => (m.peak_torque_Nm / 1e3) * Math.min(1, m.base_speed_rpm / Math.max(Math.abs(n), 1e-9)));
  const lowest = backward ? -m.max_speed_rpm : 0;
  // the torque's limits where the motor is: the peak envelope at its speed (falling above the base speed)
  // and the rated torque (the RMS limit), both signs
  const atSpeed = c.motor_speed_rpm.map((n) => (m.peak_torque_Nm / 1e3) * Math.min(1, m.base_speed_rpm / Math.max(Math.abs(n), 1e-9)));
  const rated = m.rated_torque_Nm / 1e3;
  const limit = (y, name, color, showlegend) => ({ x, y, name, legendgroup: name, showlegend, line: { dash: "dash", width: 1.2, color }, hoverinfo: "name+y" });
  const traces = [
    { x, y: torque, name: "motor torque [kN m]", line: { color: "#d62728" } },
    limit(atSpeed, "drive.motor.peak_torque_Nm: the envelope at the motor's speed", "#b22222", true),
    limit(atSpeed.map((v) => -v), "drive.motor.peak_torque_Nm: the envelope at the motor's speed", "#b22222", false),
    limit(x.map(() => rated), `drive.motor.rated_torque_Nm = ${rated} kN m (RMS limit)`, "#e08000", true),
    limit(x.map(() => -rated), `drive.motor.rated_torque_Nm = ${rated} kN m (RMS limit)`, "#e08000", false),
    { x, y: c.motor_power_kW, name: "motor power [kW]", yaxis: "y2", line: { color: "#17becf" } },
    { x: c.motor_speed_rpm, y: torque, xaxis: "x2", yaxis: "y3", mode: "lines", name: "cycle in the torque–speed plane", line: { color: "#d62728" }, showlegend: false },
    { x: speeds, y: envelope, xaxis: "x2", yaxis: "y3", name: "peak envelope", line: { dash: "dash", color: "#b22222" }, showlegend: false },
    { x: speeds, y: envelope.map((v) => -v), xaxis: "x2", yaxis: "y3", showlegend: false, line: { dash: "dash", color: "#b22222" } },
    { x: [lowest, m.max_speed_rpm], y: [rated, rated], xaxis: "x2", yaxis: "y3", showlegend: false, name: "rated torque", line: { dash: "dash", color: "#e08000" } },
    { x: [lowest, m.max_speed_rpm], y: [-rated, -rated], xaxis: "x2", yaxis: "y3", showlegend: false, name: "rated torque", line: { dash: "dash", color: "#e08000" } },
  ];
  const round = ROUND_TICKS;
  const layout = {
    ...cycleChartLayout(r, x, axis, -0.15),
    xaxis: { domain: [0, 0.58], anchor: "y2", title: { text: xAxisTitle(axis) } },
    yaxis: { ...round, domain: [0.53, 1], anchor: "x", title: { text: "motor torque [kN m]" } },
    yaxis2: { ...round, domain: [0, 0.45], anchor: "x", zeroline: true, title: { text: "motor power [kW]" } },
    xaxis2: { ...round, domain: [0.7, 1], title: { text: "motor speed [rpm]" }, anchor: "y3" },
    yaxis3: { ...round, anchor: "x2", title: { text: "torque [kN m]" } },
  };
  Plotly.react(el, traces, layout, { responsive: true, displaylogo: false });
}

// the drive's electrical side (result.power, the trajectory's power columns): shaft, bus and grid power with
// the mean bus power and the grid's limit, and the storage's energy between empty and full (energy.png's)
function drawEnergy(r, c, x, axis) {
  const el = $("#energy-chart");
  const p = r.power;
  if (!p || !c.grid_power_kW) { Plotly.purge(el); el.style.display = "none"; return; }
  el.style.display = "block";
  const line = (y, name, color, dash, yaxis) => ({ x, y, name, yaxis, hoverinfo: "name+y", line: { color, dash, width: dash ? 1.2 : 1.6 } });
  const flat = (v) => x.map(() => v);
  const traces = [
    line(c.motor_power_kW, "shaft power [kW]", "#17becf"),
    line(c.bus_power_kW, "bus power [kW]", "#7f7f7f"),
    line(c.grid_power_kW, `grid power [kW] (peak ${p.grid_peak_kW.toFixed(0)} kW)`, "#9467bd"),
    line(flat(p.mean_bus_power_kW), `mean bus power ${p.mean_bus_power_kW.toFixed(0)} kW`, "#555555", "dot"),
  ];
  if (p.grid_limit_kW !== null && p.grid_limit_kW !== undefined) {
    traces.push(line(flat(p.grid_limit_kW), `drive.grid.peak_power_kW = ${p.grid_limit_kW} kW`, "#b22222", "dash"));
  }
  const storage = p.storage_usable_kJ > 0;
  if (storage) {
    traces.push(line(c.storage_energy_kJ, "stored energy [kJ]", "#2ca02c", undefined, "y2"));
    traces.push(line(flat(p.storage_usable_kJ), `drive.storage.usable_energy_kJ = ${p.storage_usable_kJ} kJ`, "#2ca02c", "dash", "y2"));
    traces.push(line(flat(0), "storage empty", "#2ca02c", "dot", "y2"));
  }
  const round = ROUND_TICKS;
  const layout = {
    ...cycleChartLayout(r, x, axis, -0.18),
    xaxis: { anchor: storage ? "y2" : "y", title: { text: xAxisTitle(axis) } },
    yaxis: { ...round, domain: storage ? [0.4, 1] : [0, 1], zeroline: true, title: { text: "power [kW]" } },
    yaxis2: { ...round, domain: [0, 0.32], anchor: "x", rangemode: "tozero", title: { text: "storage [kJ]" } },
  };
  Plotly.react(el, traces, layout, { responsive: true, displaylogo: false });
}

// ---- the mechanism at a crank angle -----------------------------------------------------------------
function drawMechanism() {
  const m = state.last && state.last.mechanism;
  const svg = $("#mechanism-svg");
  if (!m) { svg.innerHTML = ""; return; }
  const angle = Number($("#crank-angle").value);
  $("#crank-angle-value").textContent = angle.toFixed(0) + " deg";
  const k = nearest(m.angles_deg, angle);
  const names = Object.keys(m.joints);
  let xs = [], ys = [];
  for (const n of names) { xs = xs.concat(m.joints[n][0]); ys = ys.concat(m.joints[n][1]); }
  const pad = 0.08 * Math.max(Math.max(...xs) - Math.min(...xs), Math.max(...ys) - Math.min(...ys));
  const x0 = Math.min(...xs) - pad, x1 = Math.max(...xs) + pad, y0 = Math.min(...ys) - pad, y1 = Math.max(...ys) + pad;
  svg.setAttribute("viewBox", `${x0} ${-y1} ${x1 - x0} ${y1 - y0}`);
  const at = (n) => [m.joints[n][0][k], -m.joints[n][1][k]]; // SVG's y points down
  const size = (x1 - x0) / 60;
  const parts = [];
  const slideX = m.joints.slide[0][k];
  parts.push(`<line class="guide" x1="${slideX}" y1="${-y1}" x2="${slideX}" y2="${-y0}" />`);
  for (const bar of m.bars) {
    const pts = bar.map(at);
    if (pts.length > 2) parts.push(`<polygon class="bar" points="${pts.map((p) => p.join(",")).join(" ")}" />`);
    else parts.push(`<line class="bar" x1="${pts[0][0]}" y1="${pts[0][1]}" x2="${pts[1][0]}" y2="${pts[1][1]}" />`);
  }
  const [sx, sy] = at("slide");
  parts.push(`<rect class="slide" x="${sx - 4 * size}" y="${sy - 1.5 * size}" width="${8 * size}" height="${3 * size}" />`);
  for (const n of names) {
    const [x, y] = at(n);
    const cls = m.fixed.includes(n) ? "joint fixed" : "joint";
    parts.push(`<circle class="${cls}" cx="${x}" cy="${y}" r="${size}"><title>${n}</title></circle>`);
  }
  svg.innerHTML = parts.join("");
  svg.dataset.angle = String(m.angles_deg[k]);
}

function followChart(event) {  // the drawing follows the crank angle under the mouse
  if (!state.last || !event.points || !event.points.length) return;
  const c = state.last.curves, x = event.points[0].x;
  const angle = $("#x-axis").value === "time" ? c.crank_angle_deg[nearest(c.time_s, x)] : x;
  $("#crank-angle").value = String(Math.round(((angle % 360) + 360) % 360));
  drawMechanism();
}

// ---- cases, uploads, downloads ----------------------------------------------------------------------
let loads = 0; // the case loaded last is the one shown, whatever order the answers come in
async function loadCase(name) {
  const mine = ++loads;
  const answer = await readJson(fetch("/api/case/" + encodeURIComponent(name)));
  if (mine === loads) showLoaded(answer);
}

function showLoaded(answer) {
  const read = answer.case != null; // a case read, else the answer says what is wrong with it
  $("#load-message").textContent = read ? "" : answer.message;
  if (!read) return;
  state.label = answer.label;
  state.data = answer.case;
  state.pinned = null; // a pinned plan belongs to the case it was pinned on
  state.newCase = true; // until it has a plan, no other case's plan stays on screen
  $("#case-label").textContent = answer.label;
  forgetHistory();
  buildForm(answer.case);
  solveNow();
}

async function upload(file) {
  if (file.size > state.meta.max_case_bytes) { // the server's own line, without a refused request
    showLoaded({ message: `${file.name}: too large for a case file (more than ${state.meta.max_case_bytes} bytes)` });
    return;
  }
  const body = new FormData();
  body.append("file", file);
  const mine = ++loads;
  const answer = await readJson(fetch("/api/upload", { method: "POST", body }));
  if (mine !== loads) return; // another case picked or opened since
  showLoaded(answer);
  if (answer.case != null) showUploaded(answer.label);
}

// the case list names the uploaded case (so that picking a listed case again loads it)
function showUploaded(label) {
  const select = $("#case-select");
  let option = select.querySelector("option[data-uploaded]");
  if (!option) {
    option = new Option("", "", false, false);
    option.dataset.uploaded = "1";
    option.disabled = true;
    select.add(option, 0);
  }
  option.textContent = `uploaded: ${label}`;
  select.value = "";
  option.selected = true;
}

async function download(name, cam) {
  const data = caseFromForm();
  const response = await post("/api/download/" + name, { session: SESSION, label: state.label, case: data, cam });
  if (!response.ok) {
    const answer = await readJson(Promise.resolve(response));
    if (cam) { $("#cam-message").textContent = answer.message; return; }
    clearMessages();
    showMessage(answer.field || "", answer.message);
    return;
  }
  const blob = await response.blob();
  const a = document.createElement("a");
  a.href = URL.createObjectURL(blob);
  a.download = name === "case.yaml" ? `${data.name || "case"}.yaml` : name;
  document.body.appendChild(a);
  a.click();
  setTimeout(() => { URL.revokeObjectURL(a.href); a.remove(); }, 1000);
}

// ---- the cam for the controller: the confirmed plan on screen, proved as its controller runs it -------------
function camOptions() {
  return { target: $("#cam-target").value, interpolation: $("#cam-interpolation").value, count: $("#cam-count").value.trim() || "auto" };
}

function camReset() { // a new plan or other options: the cam must be proved again before it is downloaded
  $("#cam-download").disabled = true;
  $("#cam-proof").textContent = "";
  $("#cam-proof").className = "muted";
  $("#cam-message").textContent = "";
  state.camFile = null;
}

function camInterpolations() { // the interpolations the target takes
  const select = $("#cam-interpolation"), before = select.value;
  select.innerHTML = "";
  for (const name of state.meta.cam.targets[$("#cam-target").value]) select.add(new Option(name, name));
  if ([...select.options].some((o) => o.value === before)) select.value = before;
}

async function camProve() {
  camReset();
  $("#cam-proof").textContent = "proving…";
  const asked = state.shownSeq;
  const answer = await readJson(post("/api/cam", { session: SESSION, label: state.label, case: caseFromForm(), cam: camOptions() }));
  if (asked !== state.shownSeq) return; // another plan on screen since: its cam is not this one
  $("#cam-proof").textContent = "";
  if (answer.status !== OUTCOME.VERIFIED) { $("#cam-message").textContent = answer.message; return; }
  const speed = answer.highest_speed_pct.toFixed(2);
  $("#cam-proof").textContent = `${answer.file}: ${answer.points} points, slide within ${answer.deviation_mm.toPrecision(3)} mm of the plan; ` +
    `every limit holds up to ${speed} % of the plan's master speed` + (answer.above.length ? ` (above: ${answer.above.join(", ")})` : "");
  $("#cam-proof").title = answer.lines.join("\n");
  $("#cam-proof").className = "held";
  state.camFile = answer.file;
  $("#cam-download").disabled = false;
}

// a field's help, in the one fixed box above the form (shown on focus or hover; the form never moves)
function showHelp(event) {
  const row = event.target.closest && event.target.closest(".field");
  const help = row && row.querySelector(".help");
  if (help) $("#field-help").textContent = help.textContent;
}

async function start() {
  state.meta = await (await fetch("/api/meta")).json();
  OUTCOME = Object.freeze(state.meta.outcomes);
  const buttons = $("#downloads");
  for (const d of state.meta.downloads) { // the outputs' registry: every file the page offers
    const b = document.createElement("button");
    b.type = "button";
    b.dataset.download = d.name;
    b.textContent = d.title;
    buttons.appendChild(b);
  }
  const select = $("#case-select");
  for (const name of state.meta.cases) select.add(new Option(name, name));
  select.addEventListener("change", () => { $("#recipe-select").value = ""; loadCase(select.value); }); // a recipe reopens from its list
  $("#upload").addEventListener("change", (e) => {
    const file = e.target.files.length ? e.target.files[0] : null;
    e.target.value = ""; // the same file chosen again is a new upload
    if (file) upload(file);
  });
  buildPanels();
  let resizeTimer = null;
  window.addEventListener("resize", () => { clearTimeout(resizeTimer); resizeTimer = setTimeout(() => { if (state.last) drawCharts(); }, 150); });
  $("#undo").addEventListener("click", () => moveInHistory(-1));
  $("#redo").addEventListener("click", () => moveInHistory(+1));
  document.addEventListener("keydown", (e) => { // Ctrl+Z / Ctrl+Y outside a text box (a box keeps its own undo)
    if (!(e.ctrlKey || e.metaKey) || e.target.matches("input[type=text], input:not([type])")) return;
    if (e.code === "KeyZ" && !e.shiftKey) { e.preventDefault(); moveInHistory(-1); } // the key's place: any layout, Caps Lock
    else if (e.code === "KeyY" || (e.code === "KeyZ" && e.shiftKey)) { e.preventDefault(); moveInHistory(+1); }
  });
  if (state.meta.recipes) {
    listRecipes();
    $("#recipe-save").addEventListener("click", saveRecipe);
    $("#recipe-select").addEventListener("change", (e) => openRecipe(e.target.value));
  } else {
    document.querySelector("header .recipes").hidden = true;
  }
  $("#x-axis").addEventListener("change", () => { if (state.last) drawCharts(); });
  $("#crank-angle").addEventListener("input", drawMechanism);
  $("#pin").addEventListener("click", () => { if (state.last) { state.pinned = state.last; showPin(); drawCharts(); } });
  $("#unpin").addEventListener("click", () => { state.pinned = null; if (state.last) { showPin(); drawCharts(); } });
  $("#download-case").addEventListener("click", () => download("case.yaml"));
  for (const kind of ["focusin", "mouseover"]) $("#case-form").addEventListener(kind, showHelp);
  for (const target of Object.keys(state.meta.cam.targets)) $("#cam-target").add(new Option(target, target));
  camInterpolations();
  $("#cam-target").addEventListener("change", () => { camInterpolations(); camReset(); });
  for (const id of ["#cam-interpolation", "#cam-count"]) $(id).addEventListener("change", camReset);
  $("#cam-prove").addEventListener("click", camProve);
  $("#cam-download").addEventListener("click", () => { if (state.camFile) download(state.camFile, camOptions()); });
  for (const b of document.querySelectorAll("[data-download]")) b.addEventListener("click", () => download(b.dataset.download));
  if (state.meta.initial) { select.value = state.meta.initial; loadCase(state.meta.initial); }
  else setStatus("no case: upload one", "failed");
}

start();
