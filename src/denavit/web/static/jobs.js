/* denavit workbench, the long work: jobs run by the server in their own processes (the symbolic T_0n, the singular
 * sets, the report, the check, the workspace, the reachability map), polled for progress, cancelled when superseded or when the page goes.
 * Uses the page's state through window.workbench.internals (workbench.js, loaded first).
 */
(function () {
  "use strict";
  var wb = window.workbench, I = wb.internals, $ = I.$, post = I.post, download = I.download;
  var good = null, q = [];
  function sync() { good = I.good(); q = I.q(); }   // the page's current table and sliders

  var running = {};          // this page's jobs by id, cancelled when the page goes away
  // this page's name for its panels: the server cancels a panel's running job when the panel starts the next one
  var pageId = Math.random().toString(36).slice(2, 12);
  function runJob(kind, payload, onProgress, onDone) {
    var job = { id: null, stopped: false }, polls = 0;
    post("/api/jobs", { kind: kind, payload: payload, slot: pageId + ":" + kind }).then(function (r) {
      if (r._status !== 200) { if (!job.stopped) onDone(null, r.error, r); return; }
      job.id = r.id;
      if (job.stopped) { cancelJob(job); return; }   // superseded before it started
      running[job.id] = job;
      (function poll() {
        if (job.stopped) return;
        fetch("/api/jobs/" + job.id).then(function (x) { return x.json(); }).then(function (s) {
          if (job.stopped) return;
          if (s.state === "running") { onProgress(s.progress); setTimeout(poll, ++polls < 40 ? 50 : 250); return; }
          delete running[job.id];
          onDone(s.state === "done" ? s.result : null, s.state === "done" ? "" : s.error, s);
        });
      })();
    });
    return job;
  }
  function cancelJob(job) {
    if (!job) return;
    job.stopped = true;
    if (job.id) { delete running[job.id]; post("/api/jobs/" + job.id + "/cancel", {}); }
  }
  window.addEventListener("pagehide", function () {
    Object.keys(running).forEach(function (id) {
      navigator.sendBeacon("/api/jobs/" + id + "/cancel", new Blob(["{}"], { type: "application/json" }));
    });
  });

  var formulaJob = null;
  function startFormula() {
    cancelJob(formulaJob);
    $("formula-status").textContent = "deriving…";
    var t0 = performance.now(), sent = good.doc;
    formulaJob = runJob("formula", { robot: sent }, function () {}, function (res, err, st) {
      if (!res) { $("formula-status").textContent = err; return; }
      var box = $("formula"); box.innerHTML = "";
      res.steps.forEach(function (s) {
        var el = document.createElement(s.math ? "div" : "p");
        if (s.math && window.katex) katex.render(s.math, el, { displayMode: true, throwOnError: false });
        else el.textContent = s.math || s.text;
        box.appendChild(el);
      });
      wb.formulaSeconds = (performance.now() - t0) / 1000;
      wb.formulaCpu = st.cpu_seconds; wb.formulaDoc = sent;   // the job's own CPU time, and the table it derived
      $("formula-status").textContent = "derived in " + wb.formulaSeconds.toFixed(2) + " s (" + st.cpu_seconds + " s of CPU)";
    });
  }

  var reportJob = null, report = null;
  function startReport() {
    sync();
    $("report-start").disabled = true; $("report-cancel").disabled = false;
    $("report-downloads").hidden = true; $("report-sections").innerHTML = "";
    var typed = I.qTyped() && I.qTyped().values.every(function (v, k) { return Math.abs(v - q[k]) < 1e-12; });
    reportJob = runJob("report", { robot: good.doc, q: typed ? I.qTyped().text : q, qd: $("qd").value.trim(),
                                   wrench: $("wrench").value.trim(), pdf: $("report-pdf").checked }, function (p) {
      var last = p[p.length - 1] || "starting", m = /section (\d+)\/(\d+)/.exec(last);
      $("report-status").textContent = last;
      if (m) $("report-progress").value = (m[1] - 1) / m[2];
    }, function (res, err) {
      $("report-start").disabled = false; $("report-cancel").disabled = true;
      $("report-progress").value = res ? 1 : 0;
      if (!res) { $("report-status").textContent = err; return; }
      report = res;
      $("report-status").textContent = res.title + [res.note, res.pdf_note].filter(Boolean).map(function (n) { return " (" + n + ")"; }).join("");
      document.querySelector("#report-downloads [data-fmt=pdf]").hidden = !res.pdf;
      res.sections.forEach(function (s, i) {
        var li = document.createElement("li"), a = document.createElement("a");
        a.href = "#"; a.textContent = s.title + (s.status === "done" ? "" : " — " + s.status + ": " + s.reason);
        a.addEventListener("click", function (e) {
          e.preventDefault();
          var t = $("report").contentDocument.getElementById(s.key); if (t) t.scrollIntoView();
        });
        li.appendChild(a); $("report-sections").appendChild(li);
      });
      $("report").hidden = false; $("report").srcdoc = res.html; $("report-downloads").hidden = false;
    });
  }

  function startCheck() {
    sync();
    var file = $("check-file").files[0];
    var textP = file ? file.text() : Promise.resolve($("check-text").value);
    textP.then(function (text) {
      $("check-status").textContent = "checking…"; $("check-summary").textContent = "";
      var payload = { text: text, kind: $("check-kind").value, use_arm: $("check-use-arm").checked,
                      robot: good ? good.doc : I.doc(), name: file ? file.name : "pasted report" };
      runJob("check", payload, function (p) { $("check-status").textContent = p[p.length - 1] || "checking…"; }, function (res, err) {
        if (!res) { $("check-status").textContent = err; return; }
        $("check-status").textContent = "";
        var s = res.summary;
        $("check-summary").textContent = Object.keys(s).filter(function (k) { return s[k]; })
          .map(function (k) { return s[k] + " " + k; }).join(", ") || "nothing to judge was found";
        $("check-summary").dataset.summary = JSON.stringify(s);
        $("checked").hidden = !res.html; $("claims-annotated").hidden = res.kind !== "claims";
        $("check-text-result").hidden = true;
        if (res.html) $("checked").srcdoc = res.html;
        if (res.kind === "claims") annotateClaims(res);
      });
    });
  }

  // a claims file shown as written, each claim's verdict marked beside its first line, the message after its last
  var MARKS = { correct: "✓", incorrect: "✗", ambiguous: "?", unreadable: "!" };
  function annotateClaims(res) {
    var box = $("claims-annotated"), rows = res.source.split("\n"), at = {}, after = {}, loose = [];
    box.innerHTML = "";
    res.claims.forEach(function (c) {
      if (c.line) { (at[c.line] = at[c.line] || []).push(c); (after[c.end_line] = after[c.end_line] || []).push(c); }
      else loose.push(c);
    });
    function note(c) {
      var d = document.createElement("div");
      d.className = "claim-note v-" + c.verdict;
      d.textContent = c.verdict + " — " + c.id + " (" + c.quantity + "): " + c.message +
        (c.hints.length ? "  hint: " + c.hints.join("; ") : "");
      return d;
    }
    rows.forEach(function (text, i) {
      var n = i + 1, line = document.createElement("div"), gutter = document.createElement("span"), code = document.createElement("code");
      line.className = "claim-line"; gutter.className = "gutter"; gutter.textContent = n;
      (at[n] || []).forEach(function (c) {
        var m = document.createElement("span");
        m.className = "verdict v-" + c.verdict; m.textContent = MARKS[c.verdict] || "·";
        m.dataset.verdict = c.verdict; m.dataset.claim = c.id; m.dataset.line = n; m.title = c.verdict + ": " + c.message;
        gutter.appendChild(m);
      });
      code.textContent = text; line.appendChild(gutter); line.appendChild(code); box.appendChild(line);
      (after[n] || []).forEach(function (c) { box.appendChild(note(c)); });
    });
    loose.forEach(function (c) { box.appendChild(note(c)); });
    res.notes.forEach(function (t) { var d = document.createElement("div"); d.className = "notes"; d.textContent = t; box.appendChild(d); });
  }

  // ---- singular sets: derived once (a job), the nearest one named at every slider move -------------------
  var singular = null, singDoc = null;
  function startSingularities() {
    sync();
    $("sing-start").disabled = true; $("sing-status").textContent = "deriving…";
    var sent = good.doc;
    runJob("singularities", { robot: sent }, function (p) { $("sing-status").textContent = p[p.length - 1] || "deriving…"; },
      function (res, err) {
        $("sing-start").disabled = false;
        if (!res) { $("sing-status").textContent = err; return; }
        singular = res; singDoc = sent;
        if (wb.refresh) wb.refresh();   // the measures on the task rows just found
        $("sing-status").textContent = res.everywhere ? "singular everywhere: " + res.reason :
          res.conditions.length ? res.measure + " vanishes when:" : (res.complete ? "no singular configuration" :
          "not solved symbolically (non-square J: all minors vanish together)");
        var list = $("sing-list"); list.innerHTML = "";
        res.conditions.forEach(function (c) {
          var li = document.createElement("li"), m = document.createElement("span");
          if (window.katex) katex.render(c.latex, m, { throwOnError: false }); else m.textContent = c.latex;
          li.appendChild(m); li.appendChild(document.createTextNode(" — " + c.kind + ": " + c.explanation));
          list.appendChild(li);
        });
        showNearest();
      });
  }
  function wrap(x) { return Math.abs(Math.atan2(Math.sin(x), Math.cos(x))); }
  function showNearest() {
    sync();
    var out = $("sing-nearest");
    if (singular && singDoc !== good.doc) {   // the table changed: those conditions were another arm's
      singular = null; $("sing-list").innerHTML = ""; $("sing-status").textContent = "the table changed: find them again";
    }
    if (!singular) { out.textContent = ""; return; }
    var best = null;
    singular.conditions.forEach(function (c) {
      c.solutions.forEach(function (s) {
        var k = parseInt(s.variable.slice(1), 10) - 1, rev = good.info.joint_types[k] === "revolute";
        s.values.forEach(function (v) {
          var d = rev ? wrap(q[k] - v) : Math.abs(q[k] - v);
          if (!best || d < best.d) best = { d: d, text: s.variable + " = " + v.toFixed(4) + " (" + c.kind + ")", unit: rev ? " rad" : " m" };
        });
      });
    });
    out.textContent = best ? "nearest: " + best.text + ", " + best.d.toFixed(4) + best.unit + " away" : "";
    out.dataset.distance = best ? best.d : "";
  }

  var wsJob = null;
  function startWorkspace() {
    sync();
    var n = number("ws-samples");   // 1e8 as typed; the server names a bad count
    $("ws-start").disabled = true; $("ws-cancel").disabled = false; $("ws-progress").value = 0;
    wsJob = wb.wsJob = runJob("workspace", { robot: good.doc, samples: n }, function (p) {
      var last = p[p.length - 1] || "starting", m = /^([\d.]+)%/.exec(last);
      $("ws-status").textContent = last;
      if (m) $("ws-progress").value = 0.95 * m[1] / 100; else if (/drawing/.test(last)) $("ws-progress").value = 0.95;
    }, function (res, err) {
      $("ws-start").disabled = false; $("ws-cancel").disabled = true; $("ws-progress").value = res ? 1 : 0;
      if (!res) { $("ws-status").textContent = err; return; }
      var unit = res.planar ? " m²" : " m³";
      $("ws-status").textContent = res.samples + " samples, reach " + res.reach.toFixed(3) + " m, " +
        (res.planar ? "area " : "volume ") + (res.planar ? res.area : res.volume).toFixed(3) + unit +
        " (between " + res.low.toFixed(3) + " and " + res.high.toFixed(3) + unit + ")";
      $("ws-picture").src = "data:image/png;base64," + res.png; $("ws-picture").hidden = false;
    });
  }
  // the reachability map (denavit reachability): the library's progress line is the job's, a screen of position
  // samples (the first fifth of the bar) then the voxels
  var reachJob = null;
  function number(id) { var t = $(id).value.trim(), x = Number(t); return t && isFinite(x) ? x : t; }
  function startReach() {
    sync();
    $("reach-start").disabled = true; $("reach-cancel").disabled = false; $("reach-progress").value = 0;
    $("reach-picture").hidden = true;
    reachJob = wb.reachJob = runJob("reachability", { robot: good.doc, resolution: number("reach-resolution"),
                                                      orientations: number("reach-orientations") }, function (p) {
      var last = p[p.length - 1] || "starting", m = /^([\d.]+)%.*\b(samples|voxels)\b/.exec(last);
      $("reach-status").textContent = last;
      if (m) $("reach-progress").value = m[2] === "samples" ? 0.2 * m[1] / 100 : 0.2 + 0.8 * m[1] / 100;
    }, function (res, err) {
      $("reach-start").disabled = false; $("reach-cancel").disabled = true; $("reach-progress").value = res ? 1 : 0;
      if (!res) { $("reach-status").textContent = err; return; }
      $("reach-status").textContent = res.voxels_reached + " of " + res.voxels_tested + " voxels reached (" +
        res.reachable_volume.toFixed(3) + " m³), at half of the orientations or more " + res.dexterous_volume.toFixed(3) +
        " m³; " + res.method + " IK";
      $("reach-picture").src = "data:image/png;base64," + res.png; $("reach-picture").hidden = false;
    });
  }
  $("reach-start").addEventListener("click", startReach);
  $("reach-cancel").addEventListener("click", function () {
    cancelJob(reachJob); $("reach-start").disabled = false; $("reach-cancel").disabled = true;
    $("reach-status").textContent = "cancelled"; $("reach-progress").value = 0;
  });
  $("report-start").addEventListener("click", startReport);
  $("report-cancel").addEventListener("click", function () {
    cancelJob(reportJob); $("report-start").disabled = false; $("report-cancel").disabled = true;
    $("report-status").textContent = "cancelled"; $("report-progress").value = 0;
  });
  document.querySelectorAll("#report-downloads button").forEach(function (b) {
    b.addEventListener("click", function () {
      var f = b.dataset.fmt, type = { html: "text/html", md: "text/markdown", tex: "application/x-tex", pdf: "application/pdf" }[f];
      var data = report[f];
      sync();
      if (f === "pdf") data = Uint8Array.from(atob(report.pdf), function (c) { return c.charCodeAt(0); });
      download(data, (good.info.name || "report") + "-report." + f, type);
    });
  });
  $("check-file").addEventListener("change", function () {
    var f = this.files[0], m = f && /\.(md|markdown|tex|txt|ya?ml)$/i.exec(f.name);
    $("check-kind").value = m ? ({ markdown: "md", yml: "yaml" }[m[1].toLowerCase()] || m[1].toLowerCase()) : "auto";
  });
  $("check-start").addEventListener("click", startCheck);
  $("ws-start").addEventListener("click", startWorkspace);
  $("sing-start").addEventListener("click", startSingularities);
  $("ws-cancel").addEventListener("click", function () {
    cancelJob(wsJob); $("ws-start").disabled = false; $("ws-cancel").disabled = true;
    $("ws-status").textContent = "cancelled"; $("ws-progress").value = 0;
  });
  wb.onRobot = function () { sync(); startFormula(); };
  wb.onPose = showNearest;
  // the measures' task rows: those the singularity analysis chose (vx, vy for a planar arm), for this table
  wb.taskRows = function () { sync(); return singular && singDoc === good.doc ? singular.rows : null; };
})();
