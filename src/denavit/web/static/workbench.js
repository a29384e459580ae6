/* denavit workbench: the page edits a robot file (its DH table), the server answers (kinematics, IK, dynamics);
 * the long work (jobs) is in jobs.js.  The 3-D view is denavit's own viewer page (viz/assets/viewer.js) in an iframe, one slider per joint;
 * this script listens to its sliders.  No dependencies besides the bundled KaTeX.
 */
(function () {
  "use strict";
  var $ = function (id) { return document.getElementById(id); };
  var FIELDS = ["a", "alpha", "d", "theta"];
  var doc = null;            // the robot-file mapping being edited
  var good = null;           // {doc, info} of the last table the server read
  var q = [];                // the sliders' joint values
  // for tests and tools: slider -> T/J written (latencies) and -> the next animation frame (painted), in ms
  var wb = window.workbench = { latencies: [], painted: [], seq: 0, shown: -1, robotLoads: 0, kinCount: 0 };

  // ---- server -------------------------------------------------------------------------------------
  function post(path, body) {
    return fetch(path, { method: "POST", headers: { "Content-Type": "application/json" }, body: JSON.stringify(body) })
      .then(function (r) { return r.json().then(function (data) { data._status = r.status; return data; }); });
  }
  function status(text) { $("status").textContent = text; }
  function fmt(x, w) { if (x === null) return "nan"; var s = (Math.abs(x) < 5e-5 ? 0 : x).toFixed(4); return (s.charAt(0) === "-" ? "" : " ") + s; }
  function matText(M) { return M.map(function (r) { return r.map(fmt).join("  "); }).join("\n"); }
  function vecText(v) { return v.map(fmt).join("  "); }

  // ---- the table ----------------------------------------------------------------------------------
  function kindOf(row) {
    var has = function (f) { return /(^|[^A-Za-z0-9_])q\d*([^A-Za-z0-9_(]|$)/.test(String(row[f] === undefined ? "" : row[f])); };
    return has("theta") ? "revolute" : has("d") ? "prismatic" : "fixed";
  }
  function stripQ(text) {
    var t = String(text).trim(), m;
    if (/^q\d*$/.test(t)) return "0";
    if ((m = /^q\d*\s*\+\s*(.+)$/.exec(t))) return m[1];
    if ((m = /^q\d*\s*-\s*(.+)$/.exec(t))) return "-(" + m[1] + ")";
    if ((m = /^(.+?)\s*\+\s*q\d*$/.exec(t))) return m[1];
    return t;
  }
  function addQ(text) { var t = String(text).trim(); return (t === "" || t === "0") ? "q" : "q + " + t; }

  function renderTable() {
    var body = $("dh").tBodies[0];
    body.innerHTML = "";
    doc.joints.forEach(function (row, i) {
      var tr = document.createElement("tr");
      tr.innerHTML = "<td>" + (i + 1) + "</td>";
      var td = document.createElement("td"), sel = document.createElement("select");
      [["revolute", "R"], ["prismatic", "P"], ["fixed", "fixed"]].forEach(function (o) {
        var opt = document.createElement("option"); opt.value = o[0]; opt.textContent = o[1]; sel.appendChild(opt);
      });
      sel.value = kindOf(row); sel.className = "joint-type"; sel.dataset.row = i;
      sel.addEventListener("change", function () { setKind(i, sel.value); });
      td.appendChild(sel); tr.appendChild(td);
      FIELDS.forEach(function (f) {
        var c = document.createElement("td"), inp = document.createElement("input");
        inp.value = row[f] === undefined ? "0" : String(row[f]);
        inp.size = 9; inp.id = "cell-" + (i + 1) + "-" + f; inp.dataset.row = i; inp.dataset.field = f;
        inp.addEventListener("input", function () { doc.joints[i][f] = inp.value; tableChanged(); });
        c.appendChild(inp); tr.appendChild(c);
      });
      var del = document.createElement("td"), b = document.createElement("button");
      b.type = "button"; b.textContent = "×"; b.title = "remove row " + (i + 1);
      b.addEventListener("click", function () {
        if (doc.joints.length > 1) { if (kindOf(doc.joints[i]) !== "fixed") dropPoses(); doc.joints.splice(i, 1); renderTable(); tableChanged(); }
      });
      del.appendChild(b); tr.appendChild(del);
      body.appendChild(tr);
    });
    $("robot-name").value = doc.name || "";
    $("convention").value = doc.convention || "standard";
    $("angle-unit").value = doc.angle_unit || "rad";
    var p = doc.parameters || {};
    $("parameters").value = Object.keys(p).map(function (k) { return k + " = " + p[k]; }).join("\n");
    var mod = doc.convention === "modified";
    $("h-a").innerHTML = mod ? "a<sub>i−1</sub>" : "a<sub>i</sub>";
    $("h-alpha").innerHTML = mod ? "α<sub>i−1</sub>" : "α<sub>i</sub>";
  }
  function dropPoses() { delete doc.poses; }   // the named poses had one value per joint of the old table
  function setKind(i, kind) {
    var row = doc.joints[i];
    if ((kindOf(row) === "fixed") !== (kind === "fixed")) dropPoses();
    row.theta = stripQ(row.theta === undefined ? "0" : row.theta);
    row.d = stripQ(row.d === undefined ? "0" : row.d);
    if (kind === "revolute") row.theta = addQ(row.theta);
    if (kind === "prismatic") row.d = addQ(row.d);
    if (kind === "fixed") delete row.limits;
    renderTable(); tableChanged();
  }
  function readParameters() {
    var out = {};
    $("parameters").value.split("\n").forEach(function (line) {
      var k = line.indexOf("=");
      if (line.trim() === "") return;
      if (k < 0) out[line.trim()] = "";   // the server names the bad line
      else out[line.slice(0, k).trim()] = line.slice(k + 1).trim();
    });
    return out;
  }
  var editTimer = null;
  function tableChanged() {
    doc.name = $("robot-name").value;
    doc.convention = $("convention").value;
    doc.angle_unit = $("angle-unit").value;
    doc.parameters = readParameters();
    clearTimeout(editTimer);
    editTimer = setTimeout(sendTable, 150);
  }
  function markCell(err) {
    document.querySelectorAll(".bad").forEach(function (el) { el.classList.remove("bad"); el.removeAttribute("title"); });
    $("table-error").textContent = err ? err.error : "";
    if (!err || !err.cell) return;
    var el = err.cell.row ? $("cell-" + err.cell.row + "-" + err.cell.field)
      : ({ parameters: $("parameters"), convention: $("convention"), angle_unit: $("angle-unit") })[err.cell.field];
    if (el) { el.classList.add("bad"); el.title = err.error; }
  }
  function sendTable() {
    var sent = JSON.parse(JSON.stringify(doc));
    var body = { robot: sent };
    post("/api/robot", body).then(function (r) {
      if (r._status !== 200) { markCell(r); status("the table has an error: the arm shown is the last good one"); return; }
      markCell(null);
      good = { doc: sent, info: r };
      wb.robotLoads++;
      $("table-notes").textContent = r.notes.join(" · ");
      document.querySelectorAll(".joint-type").forEach(function (s) { s.value = r.rows[+s.dataset.row]; });
      status(r.name + ": " + r.dof + " joints, " + r.convention + " DH");
      var keep = q.length === r.dof ? q.slice() : null;
      loadViewer(r.viewer, keep);
      makeRateSliders(r.dof);
      var poses = $("poses");
      poses.length = 1;
      Object.keys(r.poses).forEach(function (n) { var o = document.createElement("option"); o.value = n; o.textContent = n; poses.appendChild(o); });
      if (wb.onRobot) wb.onRobot();      // jobs.js: the symbolic T_0n
    }).catch(function (e) { status("no answer from the server: " + e); });
  }

  // ---- the 3-D view and the live panels ---------------------------------------------------------------
  function viewerSliders() { var d = $("viewer").contentDocument; return good ? good.info.joint_types.map(function (_, k) { return d.getElementById("q" + (k + 1)); }) : []; }
  function loadViewer(html, keep) {
    var frame = $("viewer");
    frame.onload = function () {
      var sliders = viewerSliders();
      sliders.forEach(function (s, k) {
        s.step = "any";                                     // IK solutions and kept values exactly, not on a grid
        if (keep) { s.value = keep[k]; s.dispatchEvent(new Event("input")); }
        s.addEventListener("input", onSliders);
      });
      onSliders();
    };
    frame.srcdoc = html;
  }
  var inFlight = false, again = false, started = {};
  function onSliders() {
    q = viewerSliders().map(function (s) { return parseFloat(s.value); });
    wb.seq++;
    started[wb.seq] = performance.now();
    if (inFlight) { again = true; return; }
    sendKinematics();
  }
  function sendKinematics() {
    inFlight = true; again = false;
    var seq = wb.seq;
    post("/api/kinematics", { robot: good.doc, q: q, seq: seq, rows: wb.taskRows && wb.taskRows() }).then(function (r) {
      inFlight = false;
      if (r._status === 200) {
        $("T").textContent = matText(r.T);
        $("J").textContent = matText(r.J);
        var sub = r.rows.length === 6 ? "J" : "J[" + r.rows.join(",") + "]";
        $("measures").textContent = (r.det === null ? "" : "det " + sub + " = " + r.det.toPrecision(5) + " · ") +
          "manipulability √det(" + sub + " " + sub + "ᵀ) = " + r.manipulability.toPrecision(5) + " · σ_min = " +
          r.singular_values[r.singular_values.length - 1].toPrecision(4) +
          (r.rows.length > good.info.dof ? " (fewer joints than rows: find the singular sets to pick the task rows)" : "");
        $("T").dataset.q = JSON.stringify(r.q);
        if (wb.onPose) wb.onPose();        // jobs.js: the nearest singular set
        $("T").dataset.full = JSON.stringify(r.T);
        wb.shown = seq; wb.kinCount++;
        if (started[seq] !== undefined) {
          var t0 = started[seq];
          wb.latencies.push(performance.now() - t0);
          requestAnimationFrame(function () { wb.painted.push(performance.now() - t0); });
        }
        Object.keys(started).forEach(function (k) { if (+k <= seq) delete started[k]; });
      } else status(r.error);
      if (again) sendKinematics(); else refreshDynamics();
    }).catch(function (e) { inFlight = false; status("no answer from the server: " + e); });
  }
  function makeRateSliders(n) {   // q̇ sliders, ±2 rad/s (or m/s), written into the q̇ field
    var box = $("qd-sliders");
    if (box.children.length === n) return;
    box.innerHTML = "";
    for (var k = 0; k < n; k++) {
      var s = document.createElement("input");
      s.type = "range"; s.min = -2; s.max = 2; s.step = 0.01; s.value = 0; s.id = "qd" + (k + 1); s.title = "q̇" + (k + 1);
      s.addEventListener("input", function () {
        $("qd").value = Array.prototype.map.call(box.children, function (e) { return e.value; }).join(", ");
        refreshDynamics();
      });
      box.appendChild(s);
    }
  }
  var dynTimer = null;
  function refreshDynamics() {
    clearTimeout(dynTimer);
    dynTimer = setTimeout(function () {
      if (!good) return;
      post("/api/dynamics", { robot: good.doc, q: q, qd: $("qd").value }).then(function (r) {
        $("dyn-error").textContent = r._status === 200 ? "" : r.error;
        if (r._status === 200) { $("M").textContent = matText(r.M); $("cg").textContent = "c: " + vecText(r.c) + "\ng: " + vecText(r.g);
          $("cg").dataset.q = JSON.stringify(r.q); $("cg").dataset.qd = JSON.stringify(r.qd); }
      });
      post("/api/statics", { robot: good.doc, q: q, wrench: $("wrench").value, frame: $("wrench-frame").value }).then(function (r) {
        $("statics-error").textContent = r._status === 200 ? "" : r.error;
        if (r._status === 200) $("tau").textContent = vecText(r.tau);
      });
    }, 60);
  }

  // ---- inverse kinematics -------------------------------------------------------------------------------
  // opts: method (analytic | numeric), base (a frozen {pose, q} target: the drag pad's), shift (m, world axes),
  // follow (move the arm to the solution nearest the sliders); returns the request's promise
  function ikBody(opts) {
    var body = { robot: good.doc, q: q, method: opts.method || "analytic" }, t = $("ik-target").value.trim();
    if (opts.base) { body.q = opts.base.q; if (opts.base.pose) body.pose = opts.base.pose; }   // the target
    else if (t) body.pose = t;
    if (opts.method === "numeric") body.seed = q;                                             // where LM starts
    if (opts.shift) body.shift = opts.shift;
    if ($("ik-lock").value.trim() && body.method === "analytic") body.lock = $("ik-lock").value.trim();
    return body;
  }
  function solveIK(opts) {
    opts = opts || {};
    var body = ikBody(opts);
    return post("/api/ik", body).then(function (r) {
      var list = $("ik-list");
      list.innerHTML = "";
      $("ik-error").textContent = r._status === 200 ? "" : r.error;
      $("ik-info").textContent = "";
      if (r._status !== 200) return r;
      if (opts.shift) $("ik-target").value = r.pose.map(function (x) { return +x.toFixed(6); }).join(", ");
      $("ik-info").textContent = r.solutions.length + " solution(s) (" + r.method + ")" +
        (r.outside_limits ? ", " + r.outside_limits + " more outside the joint limits" : "") +
        (r.reason ? ": none from this q (" + r.reason + ")" : "");
      r.solutions.forEach(function (s, i) {
        var li = document.createElement("li"), b = document.createElement("button");
        b.type = "button"; b.className = "ik-solution"; b.dataset.q = JSON.stringify(s.q);
        b.textContent = "[" + s.q.map(function (x) { return x.toFixed(4); }).join(", ") + "] " + s.branch;
        b.addEventListener("click", function () {
          document.querySelectorAll(".ik-solution").forEach(function (o) { o.classList.remove("current"); });
          b.classList.add("current"); showSolution(s.q);
        });
        li.appendChild(b); list.appendChild(li);
      });
      if (opts.follow && r.solutions.length) nearest(r.solutions).click();
      return r;
    });
  }
  function nearest(solutions) {   // the listed solution closest to the sliders (max joint distance)
    var best = 0, dist = function (s) { return Math.max.apply(null, s.q.map(function (x, k) { return Math.abs(x - q[k]); })); };
    solutions.forEach(function (s, i) { if (dist(s) < dist(solutions[best])) best = i; });
    return document.querySelectorAll(".ik-solution")[best];
  }

  // the drag pad: the target moved in a plane of world axes, ±span around where the drag started
  var PLANES = { xy: [0, 1], xz: [0, 2], yz: [1, 2] }, pad = { drag: null, dot: [0, 0], busy: false, next: null };
  function drawPad() {
    var c = $("ik-pad"), g = c.getContext("2d"), w = c.width, h = c.height, ax = PLANES[$("ik-plane").value];
    g.clearRect(0, 0, w, h); g.strokeStyle = "#bbb"; g.beginPath(); g.moveTo(w / 2, 0); g.lineTo(w / 2, h);
    g.moveTo(0, h / 2); g.lineTo(w, h / 2); g.stroke();
    g.fillStyle = "#666"; g.font = "11px sans-serif"; g.fillText("xyz"[ax[0]], w - 10, h / 2 - 4); g.fillText("xyz"[ax[1]], w / 2 + 4, 10);
    g.fillStyle = "#d62728"; g.beginPath(); g.arc(w / 2 + pad.dot[0], h / 2 - pad.dot[1], 5, 0, 2 * Math.PI); g.fill();
  }
  function padShift(e) {   // the mouse's offset from the pad's centre, in metres along the plane's two axes
    var c = $("ik-pad"), r = pad.rect, half = c.width / 2, span = parseFloat($("ik-span").value) || 0.2;
    var u = Math.max(-half, Math.min(half, e.clientX - r.left - r.width / 2)),    // from the centre (borders alike)
        v = Math.max(-half, Math.min(half, r.top + r.height / 2 - e.clientY));
    pad.dot = [u, v];
    var d = [0, 0, 0], ax = PLANES[$("ik-plane").value];
    d[ax[0]] = span * u / half; d[ax[1]] = span * v / half;
    return d;
  }
  function padSolve(base, shift) {   // one request at a time; the latest move waits, with its drag's base target
    if (pad.busy) { pad.next = [base, shift]; return; }
    pad.busy = true;
    var numeric = !good.info.analytic_ik && !$("ik-lock").value.trim();
    solveIK({ method: numeric ? "numeric" : "analytic", base: base, shift: shift, follow: true }).then(function () {
      pad.busy = false; wb.padSolves = (wb.padSolves || 0) + 1;
      if (pad.next) { var n = pad.next; pad.next = null; padSolve(n[0], n[1]); }
    });
  }
  $("ik-pad").addEventListener("mousedown", function (e) {
    var t = $("ik-target").value.trim();
    pad.drag = { pose: t || null, q: q.slice() };
    pad.rect = $("ik-pad").getBoundingClientRect();   // where the pad was when pressed: the page may reflow meanwhile
    padSolve(pad.drag, padShift(e)); drawPad(); e.preventDefault();
  });
  window.addEventListener("mousemove", function (e) { if (pad.drag) { padSolve(pad.drag, padShift(e)); drawPad(); } });
  window.addEventListener("mouseup", function () { if (pad.drag) { pad.drag = null; pad.dot = [0, 0]; drawPad(); } });
  $("ik-plane").addEventListener("change", drawPad);
  wb.padIdle = function () { return !pad.busy && !pad.next && !pad.drag; };
  drawPad();
  function showSolution(sol) {
    viewerSliders().forEach(function (s, k) { s.value = sol[k]; });
    viewerSliders().forEach(function (s) { s.dispatchEvent(new Event("input")); });
  }

  function download(text, name, type) {
    var a = document.createElement("a");
    a.href = URL.createObjectURL(new Blob([text], { type: type }));
    a.download = name; document.body.appendChild(a); a.click(); a.remove();
  }

  // a typed q sets the sliders; the report then reads it exactly as typed (pi/4, not 0.7854)
  var qTyped = null;
  function setTypedQ() {
    var text = $("q-text").value.trim();
    post("/api/kinematics", { robot: good.doc, q: text }).then(function (r) {
      $("q-error").textContent = r._status === 200 ? "" : r.error;
      if (r._status !== 200) return;
      qTyped = { text: text, values: r.q };
      showSolution(r.q);
    });
  }

  function openFile() {
    var f = $("open-file").files[0];
    if (!f) return;
    f.text().then(function (text) {
      post("/api/open", { text: text, filename: f.name }).then(function (r) {
        $("open-error").textContent = r._status === 200 ? r.notes.join(" · ") : r.error;
        if (r._status === 200) loadDoc(r.robot);
      });
    });
  }

  // ---- wiring -------------------------------------------------------------------------------------------
  function loadDoc(d) { doc = d; renderTable(); sendTable(); }
  $("add-row").addEventListener("click", function () { dropPoses(); doc.joints.push({ a: "0", alpha: "0", d: "0", theta: "q" }); renderTable(); tableChanged(); });
  ["robot-name", "parameters"].forEach(function (id) { $(id).addEventListener("input", tableChanged); });
  ["convention", "angle-unit"].forEach(function (id) { $(id).addEventListener("change", function () { tableChanged(); renderTable(); }); });
  $("catalogue").addEventListener("change", function () {
    if (!this.value) return;
    post("/api/catalogue/load", { name: this.value }).then(function (r) { if (r._status === 200) loadDoc(r.robot); else status(r.error); });
  });
  $("paste-import").addEventListener("click", function () {
    post("/api/table", { text: $("paste").value }).then(function (r) {
      $("paste-error").textContent = r._status === 200 ? r.notes.join(" · ") : r.error;
      if (r._status === 200) loadDoc(r.robot);
    });
  });
  $("download-yaml").addEventListener("click", function () {
    if (!good) return;
    post("/api/robot-file", { robot: good.doc, format: "yaml" }).then(function (r) { if (r._status === 200) download(r.text, r.filename, "text/yaml"); });
  });
  $("ik-solve").addEventListener("click", function () { solveIK({}); });
  $("ik-numeric").addEventListener("click", function () { solveIK({ method: "numeric" }); });
  $("qd").addEventListener("input", refreshDynamics);
  $("wrench").addEventListener("input", refreshDynamics);
  $("wrench-frame").addEventListener("change", refreshDynamics);
  $("q-set").addEventListener("click", setTypedQ);
  $("open-file").addEventListener("change", openFile);
  $("poses").addEventListener("change", function () {
    if (this.value && good) showSolution(good.info.poses[this.value]);
  });
  wb.showSolution = showSolution;
  wb.refresh = onSliders;
  // what jobs.js uses
  wb.internals = { $: $, post: post, download: download, good: function () { return good; }, q: function () { return q; },
                   doc: function () { return doc; }, qTyped: function () { return qTyped; } };
  wb.doc = function () { return good ? good.doc : doc; };
  wb.busy = function () { return inFlight || again; };

  fetch("/api/catalogue").then(function (r) { return r.json(); }).then(function (r) {
    r.names.forEach(function (n) { var o = document.createElement("option"); o.value = n; o.textContent = n; $("catalogue").appendChild(o); });
  });
  loadDoc(JSON.parse($("start").textContent).robot);
})();
