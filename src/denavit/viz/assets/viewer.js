/* denavit viewer: forward kinematics from the embedded DH table and a canvas-2D orthographic
 * 3-D renderer with orbit (drag), pan (shift-drag or right-drag) and zoom (wheel).  No dependencies.
 * Conventions (as in denavit): standard A_i = Rz(theta) Tz(d) Tx(a) Rx(alpha);
 * modified A_i = Rx(alpha_{i-1}) Tx(a_{i-1}) Rz(theta_i) Tz(d_i); world pose = base * A_1...A_N * tool.
 */
(function () {
  "use strict";
  var DATA = JSON.parse(document.getElementById("denavit-data").textContent);
  var AXIS_COLORS = ["#d62728", "#2ca02c", "#1f77b4"];
  var TRACE_MAX = 4000;

  // ---- 4x4 matrices as arrays of 4 rows -------------------------------------------------------
  function mul(A, B) {
    var C = [[0, 0, 0, 0], [0, 0, 0, 0], [0, 0, 0, 0], [0, 0, 0, 0]];
    for (var i = 0; i < 4; i++)
      for (var j = 0; j < 4; j++) {
        var s = 0;
        for (var k = 0; k < 4; k++) s += A[i][k] * B[k][j];
        C[i][j] = s;
      }
    return C;
  }
  function rotz(t) { var c = Math.cos(t), s = Math.sin(t); return [[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]; }
  function rotx(t) { var c = Math.cos(t), s = Math.sin(t); return [[1, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1]]; }
  function tz(d) { return [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, d], [0, 0, 0, 1]]; }
  function tx(a) { return [[1, 0, 0, a], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]; }
  function col(T, j) { return [T[0][j], T[1][j], T[2][j]]; }
  function add(p, q) { return [p[0] + q[0], p[1] + q[1], p[2] + q[2]]; }
  function sub(p, q) { return [p[0] - q[0], p[1] - q[1], p[2] - q[2]]; }
  function scl(p, s) { return [p[0] * s, p[1] * s, p[2] * s]; }
  function dot(p, q) { return p[0] * q[0] + p[1] * q[1] + p[2] * q[2]; }

  function linkMatrix(row, theta, d) {
    if (DATA.convention === "standard") return mul(mul(mul(rotz(theta), tz(d)), tx(row.a)), rotx(row.alpha));
    return mul(mul(mul(rotx(row.alpha), tx(row.a)), rotz(theta)), tz(d));
  }

  /** Frames {0}..{N}, knees, end effector and joint frames at joint values q. */
  function fk(q) {
    var T = DATA.base, frames = [T], knees = [], k = 0;
    for (var i = 0; i < DATA.rows.length; i++) {
      var r = DATA.rows[i], theta = r.theta, d = r.d;
      if (r.joint === "revolute") theta += q[k++];
      else if (r.joint === "prismatic") d += q[k++];
      var prev = T;
      T = mul(T, linkMatrix(r, theta, d));
      if (DATA.convention === "standard") knees.push(sub(col(T, 3), scl(col(T, 0), r.a)));
      else knees.push(add(col(prev, 3), scl(col(prev, 0), r.a)));
      frames.push(T);
    }
    var Te = mul(T, DATA.tool), shift = DATA.convention === "standard" ? 0 : 1, jf = [];
    for (var j = 0; j < DATA.joint_rows.length; j++) jf.push(frames[DATA.joint_rows[j] + shift]);
    return { frames: frames, knees: knees, Te: Te, jointFrames: jf };
  }

  // ---- state ------------------------------------------------------------------------------------
  var q = DATA.q0.slice();
  var cam = { az: -58 * Math.PI / 180, el: 22 * Math.PI / 180, zoom: 1, pan: [0, 0] };
  var trace = [];
  var canvas = document.getElementById("view"), ctx = canvas.getContext("2d");
  var showFrames = document.getElementById("show-frames"), showTrace = document.getElementById("show-trace");

  function basis() {
    var ca = Math.cos(cam.az), sa = Math.sin(cam.az), ce = Math.cos(cam.el), se = Math.sin(cam.el);
    var toEye = [ce * ca, ce * sa, se];                 // from the target towards the eye
    var right = [-sa, ca, 0];
    var up = [-se * ca, -se * sa, ce];
    return { right: right, up: up, toEye: toEye };
  }
  function projector() {
    var B = basis(), w = canvas.clientWidth, h = canvas.clientHeight;
    var s = cam.zoom * 0.42 * Math.min(w, h) / DATA.radius, c = DATA.center;
    return function (p) {
      var v = sub(p, c);
      return [w / 2 + cam.pan[0] + s * dot(v, B.right), h / 2 + cam.pan[1] - s * dot(v, B.up), dot(v, B.toEye)];
    };
  }

  // ---- drawing: primitives collected with a depth, painted far to near -------------------------
  function seg(list, a, b, color, width, dash) { list.push({ kind: "line", pts: [a, b], color: color, width: width, dash: dash, z: (a[2] + b[2]) / 2 }); }
  function poly(list, pts, fill, stroke) {
    var z = 0; for (var i = 0; i < pts.length; i++) z += pts[i][2];
    list.push({ kind: "poly", pts: pts, fill: fill, stroke: stroke, z: z / pts.length });
  }
  function local(T, x, y, z) {
    return [T[0][0] * x + T[0][1] * y + T[0][2] * z + T[0][3], T[1][0] * x + T[1][1] * y + T[1][2] * z + T[1][3],
            T[2][0] * x + T[2][1] * y + T[2][2] * z + T[2][3]];
  }
  function cylinder(list, P, T, r, len, fill) {
    var n = 16, top = [], bot = [];
    for (var i = 0; i < n; i++) {
      var u = 2 * Math.PI * i / n;
      top.push(P(local(T, r * Math.cos(u), r * Math.sin(u), len / 2)));
      bot.push(P(local(T, r * Math.cos(u), r * Math.sin(u), -len / 2)));
    }
    for (i = 0; i < n; i++) {
      var j = (i + 1) % n;
      poly(list, [top[i], top[j], bot[j], bot[i]], fill, fill);
    }
    poly(list, top, "#f3b463", "#8a5210");
    poly(list, bot, "#f3b463", "#8a5210");
  }
  function box(list, P, T, hx, hy, hz, fill, stroke) {
    var c = [];
    for (var sx = -1; sx <= 1; sx += 2) for (var sy = -1; sy <= 1; sy += 2) for (var sz = -1; sz <= 1; sz += 2)
      c.push(P(local(T, sx * hx, sy * hy, sz * hz)));
    var faces = [[0, 1, 3, 2], [4, 5, 7, 6], [0, 1, 5, 4], [2, 3, 7, 6], [0, 2, 6, 4], [1, 3, 7, 5]];
    for (var f = 0; f < 6; f++) poly(list, faces[f].map(function (k) { return c[k]; }), fill, stroke);
  }

  // Frame labels without overprinting: labels of one axis letter whose anchors (nearly) coincide are merged
  // ("z5,6": frames sharing an axis), then each label takes the first free spot among offsets around its
  // anchor (greedy, in drawing order); a label with no free spot keeps its first choice.
  var LABEL_MERGE_PX = 6, LABEL_FONT = "11px sans-serif";
  function placeLabels(raw) {
    ctx.font = LABEL_FONT;
    var merged = [];
    raw.forEach(function (l) {
      var m = null;
      for (var i = 0; i < merged.length && !m; i++) {
        var o = merged[i];
        if (o.letter === l[1][0] && Math.abs(o.ax - l[0][0]) < LABEL_MERGE_PX &&
            Math.abs(o.ay - l[0][1]) < LABEL_MERGE_PX) m = o;
      }
      if (m) m.ids.push(l[1].slice(1));
      else merged.push({letter: l[1][0], ids: [l[1].slice(1)], ax: l[0][0], ay: l[0][1], color: l[2]});
    });
    var placed = [], out = [];
    merged.forEach(function (l) {
      var text = l.letter + l.ids.join(","), w = ctx.measureText(text).width, h = 11;
      var offs = [[3, -3], [3, h + 1], [-w - 3, -3], [-w - 3, h + 1], [-w / 2, -h - 2], [-w / 2, 2 * h],
                  [10, -10], [-w - 10, -10], [10, h + 8], [-w - 10, h + 8], [-w / 2, -2 * h - 2], [-w / 2, 3 * h]];
      var best = null;
      for (var k = 0; k < offs.length && !best; k++) {
        var x = l.ax + offs[k][0], y = l.ay + offs[k][1], box = [x - 1, y - h, x + w + 1, y + 2];
        var free = placed.every(function (b) { return box[2] < b[0] || box[0] > b[2] || box[3] < b[1] || box[1] > b[3]; });
        if (free) best = [x, y, box];
      }
      var free = !!best;
      if (!best) { var x0 = l.ax + 3, y0 = l.ay - 3; best = [x0, y0, [x0 - 1, y0 - h, x0 + w + 1, y0 + 2]]; }
      placed.push(best[2]);
      out.push({text: text, x: best[0], y: best[1], color: l.color, box: best[2], free: free});
    });
    // the placed boxes, for tests and tools: [text, [x0, y0, x1, y1], found a free spot]
    canvas.setAttribute("data-labels", JSON.stringify(out.map(function (l) { return [l.text, l.box, l.free]; })));
    return out;
  }

  function draw() {
    var dpr = window.devicePixelRatio || 1, w = canvas.clientWidth, h = canvas.clientHeight;
    if (canvas.width !== Math.round(w * dpr) || canvas.height !== Math.round(h * dpr)) {
      canvas.width = Math.round(w * dpr); canvas.height = Math.round(h * dpr);
    }
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    ctx.fillStyle = "#ffffff"; ctx.fillRect(0, 0, w, h);
    var P = projector(), g = fk(q), L = DATA.scale, r = 0.035 * L, list = [], labels = [];
    // floor grid through the base origin
    var o0 = col(DATA.base, 3), G = DATA.radius * 1.2, step = G / 5;
    for (var i = -5; i <= 5; i++) {
      seg(list, P([o0[0] + i * step, o0[1] - G, o0[2]]), P([o0[0] + i * step, o0[1] + G, o0[2]]), "#e6e6e6", 1);
      seg(list, P([o0[0] - G, o0[1] + i * step, o0[2]]), P([o0[0] + G, o0[1] + i * step, o0[2]]), "#e6e6e6", 1);
    }
    box(list, P, mul(DATA.base, tz(-1.6 * r)), 1.6 * r, 1.6 * r, 0.3 * r, "#9e9e9e", "#616161");
    // links: o_0, k_1, o_1, ..., o_N, o_e
    var pts = [col(g.frames[0], 3)];
    for (i = 0; i < g.knees.length; i++) { pts.push(g.knees[i]); pts.push(col(g.frames[i + 1], 3)); }
    pts.push(col(g.Te, 3));
    for (i = 0; i + 1 < pts.length; i++) seg(list, P(pts[i]), P(pts[i + 1]), "#3b4a5a", 5);
    for (i = 0; i < g.jointFrames.length; i++) {
      if (DATA.joint_types[i] === "revolute") cylinder(list, P, g.jointFrames[i], r, 2.6 * r, "#e0902a");
      else box(list, P, g.jointFrames[i], 0.9 * r, 0.9 * r, 2.2 * r, "#3a8fd0", "#1d4f78");
    }
    if (showTrace.checked && trace.length > 1)
      for (i = 0; i + 1 < trace.length; i++) seg(list, P(trace[i]), P(trace[i + 1]), "#9c27b0", 2);
    if (showFrames.checked) {
      var triads = g.frames.map(function (T, k) { return [T, String(k)]; });
      if (DATA.has_tool) triads.push([g.Te, "e"]);
      var len = 0.12 * L;
      triads.forEach(function (t) {
        var T = t[0], o = col(T, 3), Po = P(o);
        for (var a = 0; a < 3; a++) {
          var tip = add(o, scl(col(T, a), len));
          seg(list, Po, P(tip), AXIS_COLORS[a], 2);
          labels.push([P(add(o, scl(col(T, a), 1.18 * len))), "xyz"[a] + t[1], AXIS_COLORS[a]]);
        }
      });
    }
    list.sort(function (a, b) { return a.z - b.z; });
    ctx.lineCap = "round"; ctx.lineJoin = "round";
    list.forEach(function (e) {
      ctx.beginPath();
      ctx.moveTo(e.pts[0][0], e.pts[0][1]);
      for (var k = 1; k < e.pts.length; k++) ctx.lineTo(e.pts[k][0], e.pts[k][1]);
      if (e.kind === "poly") {
        ctx.closePath(); ctx.fillStyle = e.fill; ctx.fill();
        ctx.strokeStyle = e.stroke; ctx.lineWidth = 0.6; ctx.stroke();
      } else {
        ctx.strokeStyle = e.color; ctx.lineWidth = e.width; ctx.stroke();
      }
    });
    placeLabels(labels).forEach(function (l) {
      ctx.lineWidth = 3; ctx.strokeStyle = "rgba(255,255,255,0.85)"; ctx.strokeText(l.text, l.x, l.y);
      ctx.fillStyle = l.color; ctx.fillText(l.text, l.x, l.y);
    });
    ctx.fillStyle = "#111"; var pe = P(col(g.Te, 3));
    ctx.beginPath(); ctx.arc(pe[0], pe[1], 3.5, 0, 2 * Math.PI); ctx.fill();
    return g;
  }

  // ---- readouts -----------------------------------------------------------------------------------
  function fmt(x) { var s = (Math.abs(x) < 5e-5 ? 0 : x).toFixed(4); return (s.charAt(0) === "-" ? "" : " ") + s; }
  function update(record) {
    var g = draw();
    var T = g.Te;
    document.getElementById("readout-T").textContent = T.map(function (row) { return row.map(fmt).join("  "); }).join("\n");
    document.getElementById("T-json").textContent = JSON.stringify(T);
    document.getElementById("q-json").textContent = JSON.stringify(q);
    for (var k = 0; k < q.length; k++) {
      var rev = DATA.joint_types[k] === "revolute";
      document.getElementById("qv" + (k + 1)).textContent =
        rev ? (q[k] * 180 / Math.PI).toFixed(2) + "\u00b0 (" + q[k].toFixed(4) + " rad)" : q[k].toFixed(4) + " m";
    }
    if (record) {
      var p = col(T, 3), last = trace[trace.length - 1];
      if (!last || Math.abs(last[0] - p[0]) + Math.abs(last[1] - p[1]) + Math.abs(last[2] - p[2]) > 1e-9) {
        trace.push(p); if (trace.length > TRACE_MAX) trace.shift();
      }
    }
  }

  // ---- controls -----------------------------------------------------------------------------------
  function onSlider(k) {
    return function (ev) { q[k] = parseFloat(ev.target.value); update(true); };
  }
  // the sliders are the state: start from their values (the browser may snap q0 to the slider grid)
  for (var k = 0; k < q.length; k++) {
    var s = document.getElementById("q" + (k + 1));
    q[k] = parseFloat(s.value);
    s.addEventListener("input", onSlider(k));
  }
  document.getElementById("reset").addEventListener("click", function () {
    for (var k = 0; k < q.length; k++) {
      var el = document.getElementById("q" + (k + 1));
      el.value = DATA.q0[k];
      q[k] = parseFloat(el.value);
    }
    trace = []; update(true);
  });
  document.getElementById("clear-trace").addEventListener("click", function () { trace = []; update(true); });
  showFrames.addEventListener("change", function () { update(false); });
  showTrace.addEventListener("change", function () { update(false); });

  var drag = null;
  canvas.addEventListener("mousedown", function (e) { drag = { x: e.clientX, y: e.clientY, pan: e.shiftKey || e.button === 2 }; e.preventDefault(); });
  canvas.addEventListener("contextmenu", function (e) { e.preventDefault(); });
  window.addEventListener("mouseup", function () { drag = null; });
  window.addEventListener("mousemove", function (e) {
    if (!drag) return;
    var dx = e.clientX - drag.x, dy = e.clientY - drag.y;
    drag.x = e.clientX; drag.y = e.clientY;
    if (drag.pan) { cam.pan[0] += dx; cam.pan[1] += dy; }
    else {
      cam.az -= dx * 0.01;
      cam.el = Math.max(-1.55, Math.min(1.55, cam.el + dy * 0.01));
    }
    update(false);
  });
  canvas.addEventListener("wheel", function (e) {
    e.preventDefault();
    cam.zoom = Math.max(0.05, Math.min(50, cam.zoom * Math.exp(-e.deltaY * 0.0015)));
    update(false);
  }, { passive: false });
  window.addEventListener("resize", function () { update(false); });

  window.denavitViewer = { fk: fk, camera: cam, state: function () { return { q: q.slice(), trace: trace.slice() }; } };
  update(true);
})();
