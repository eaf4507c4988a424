// wobblog report: draws each run's signals with uPlot on one shared time
// axis, the episodes, alerts, losses and events over them, the steering
// spectrogram, and switches between the views. The numbers come from the
// data block the command wrote; nothing here analyses them.
(function () {
  "use strict";
  var errors = [];
  window.addEventListener("error", function (e) {
    errors.push(String(e.message || e.type));
  });
  var consoleError = console.error;
  console.error = function () {
    errors.push(Array.prototype.join.call(arguments, " "));
    return consoleError.apply(console, arguments);
  };

  var rides = JSON.parse(document.getElementById("report-data").textContent);
  var built = {};

  var FILL = {
    unstable: "rgba(214,39,40,0.25)",
    stable: "rgba(255,127,14,0.22)",
    alert: "rgba(255,200,0,0.3)",
    lost: "rgba(90,90,90,0.4)",
    jump: "rgba(60,90,220,0.3)"
  };
  var STROKE = { marker: "#209030", kick: "#1f4e9a", fault: "#8c3cc0" };
  var LABELS = {
    steer_deg: "steering angle (deg)",
    roll_deg: "roll angle (deg)",
    yaw_rate_dps: "yaw rate (deg/s)",
    speed_mps: "speed (m/s)",
    gyro_x_dps: "roll rate, gyro x (deg/s)",
    gyro_y_dps: "pitch rate, gyro y (deg/s)",
    accel_x_g: "acceleration x (g)",
    accel_y_g: "acceleration y (g)",
    accel_z_g: "acceleration z (g)"
  };
  var FIGURE6 = 4;

  // UTC at t s since boot through the latest sync pair at or before it
  // (the first pair before any), as the command's utc columns place it.
  function utcMs(pairs, t) {
    if (!pairs.length) return null;
    var lo = 0, hi = pairs.length;
    while (lo < hi) {
      var mid = (lo + hi) >> 1;
      if (pairs[mid][0] <= t) lo = mid + 1; else hi = mid;
    }
    var p = pairs[Math.max(lo - 1, 0)];
    return p[1] + (t - p[0]) * 1000;
  }
  function clock(ms) {
    return new Date(ms).toISOString().substring(11, 19);
  }
  function seconds(v) {
    return Math.abs(v) >= 100 ? v.toFixed(0) : v.toFixed(Math.abs(v) >= 10 ? 1 : 2);
  }

  function xAxis(ride, withUtc) {
    return {
      size: withUtc ? 48 : 28,
      values: function (u, splits) {
        return splits.map(function (s) {
          var text = seconds(s) + " s";
          var ms = withUtc ? utcMs(ride.utc, s) : null;
          return ms == null ? text : text + "\n" + clock(ms);
        });
      }
    };
  }

  // Episodes, alerts and losses as shaded stretches, markers, kicks and
  // faults as lines: drawn under the signal.
  function overlay(ride) {
    return function (u) {
      var ctx = u.ctx, b = u.bbox;
      var min = u.scales.x.min, max = u.scales.x.max;
      ctx.save();
      ctx.beginPath();
      ctx.rect(b.left, b.top, b.width, b.height);
      ctx.clip();
      ride.bands.forEach(function (band) {
        if (band.b < min || band.a > max) return;
        var x0 = u.valToPos(band.a, "x", true), x1 = u.valToPos(band.b, "x", true);
        ctx.fillStyle = FILL[band.kind];
        ctx.fillRect(x0, b.top, Math.max(x1 - x0, 2), b.height);
      });
      ride.marks.forEach(function (m) {
        if (m.t < min || m.t > max) return;
        var x = Math.round(u.valToPos(m.t, "x", true)) + 0.5;
        ctx.strokeStyle = STROKE[m.kind];
        ctx.lineWidth = 1.5;
        ctx.setLineDash(m.kind === "kick" ? [4, 3] : []);
        ctx.beginPath();
        ctx.moveTo(x, b.top);
        ctx.lineTo(x, b.top + b.height);
        ctx.stroke();
      });
      ctx.restore();
    };
  }

  // Keeps the time axis of every chart of a run the same.
  function syncScales(state) {
    return function (u, key) {
      if (key !== "x" || state.syncing) return;
      state.syncing = true;
      var min = u.scales.x.min, max = u.scales.x.max;
      state.charts.forEach(function (other) {
        if (other !== u && (other.scales.x.min !== min || other.scales.x.max !== max)) {
          other.setScale("x", { min: min, max: max });
        }
      });
      state.syncing = false;
    };
  }

  // Wheel to zoom about the cursor, shift+drag to pan.
  function navigation(state) {
    return {
      hooks: {
        ready: function (u) {
          var over = u.over;
          over.addEventListener("wheel", function (e) {
            e.preventDefault();
            var rect = over.getBoundingClientRect();
            var at = u.posToVal(e.clientX - rect.left, "x");
            var f = e.deltaY < 0 ? 0.75 : 1 / 0.75;
            zoomTo(state, at - (at - u.scales.x.min) * f, at + (u.scales.x.max - at) * f);
          }, { passive: false });
          over.addEventListener("mousedown", function (e) {
            if (!e.shiftKey) return;
            e.stopImmediatePropagation();
            e.preventDefault();
            var x0 = e.clientX, min = u.scales.x.min, max = u.scales.x.max;
            var perPx = (max - min) / over.clientWidth;
            function move(ev) {
              var d = (ev.clientX - x0) * perPx;
              zoomTo(state, min - d, max - d);
            }
            function up() {
              document.removeEventListener("mousemove", move);
              document.removeEventListener("mouseup", up);
            }
            document.addEventListener("mousemove", move);
            document.addEventListener("mouseup", up);
          }, true);
        }
      }
    };
  }

  function zoomTo(state, min, max) {
    var lo = state.span[0], hi = state.span[1];
    var width = Math.min(Math.max(max - min, 0.05), hi - lo || 1);
    min = Math.max(lo, Math.min(min, hi - width));
    state.charts[0].setScale("x", { min: min, max: min + width });
  }

  function signalChart(ride, state, column, withUtc, holder) {
    var name = ride.channels[column];
    var opts = {
      width: holder.clientWidth || 900,
      height: column < FIGURE6 ? 170 : 130,
      cursor: { sync: { key: state.key }, drag: { x: true, y: false } },
      scales: { x: { time: false } },
      legend: { live: true },
      series: [
        { label: "t (s)", value: function (u, v) { return v == null ? "-" : v.toFixed(2); } },
        { label: LABELS[name], stroke: "#1f4e9a", width: 1, spanGaps: false }
      ],
      axes: [xAxis(ride, withUtc), { label: LABELS[name], size: 62, labelSize: 18 }],
      hooks: { drawClear: [overlay(ride)], setScale: [syncScales(state)] },
      plugins: [navigation(state)]
    };
    var div = document.createElement("div");
    div.className = "chart";
    div.dataset.channel = name;
    holder.appendChild(div);
    var chart = new uPlot(opts, [ride.t, ride.columns[column]], div);
    state.charts.push(chart);
    return chart;
  }

  function spectrogramChart(ride, state, holder) {
    var spec = ride.spectrogram;
    if (!spec) {
      holder.innerHTML = "<p class=\"note\">The run is shorter than one spectrum window.</p>";
      return;
    }
    var image = new Image();
    var speed = ride.columns[ride.channels.indexOf("speed_mps")];
    function harmonic(k) {
      return speed.map(function (v) { return v == null || !ride.wheel_m ? null : k * v / ride.wheel_m; });
    }
    var cellS = spec.size[0] > 1 ? (spec.t1_s - spec.t0_s) / (spec.size[0] - 1) : 1;
    var cellHz = spec.f_max_hz / (spec.size[1] - 1);
    function drawImage(u) {
      if (!image.complete || !image.naturalWidth) return;
      var ctx = u.ctx, b = u.bbox;
      ctx.save();
      ctx.beginPath();
      ctx.rect(b.left, b.top, b.width, b.height);
      ctx.clip();
      ctx.imageSmoothingEnabled = false;
      var x0 = u.valToPos(spec.t0_s - cellS / 2, "x", true), x1 = u.valToPos(spec.t1_s + cellS / 2, "x", true);
      var y0 = u.valToPos(spec.f_max_hz + cellHz / 2, "y", true), y1 = u.valToPos(-cellHz / 2, "y", true);
      ctx.drawImage(image, x0, y0, x1 - x0, y1 - y0);
      if (ride.band_hz) {
        ctx.strokeStyle = "#ffffff";
        ctx.setLineDash([6, 4]);
        ride.band_hz.forEach(function (f) {
          var y = u.valToPos(f, "y", true);
          ctx.beginPath();
          ctx.moveTo(b.left, y);
          ctx.lineTo(b.left + b.width, y);
          ctx.stroke();
        });
      }
      ctx.restore();
    }
    var opts = {
      width: holder.clientWidth || 900,
      height: 260,
      cursor: { sync: { key: state.key }, drag: { x: true, y: false } },
      // Up to 25 Hz: the wobble band and the first wheel harmonics.
      scales: { x: { time: false }, y: { range: [0, Math.min(spec.f_max_hz, 25)] } },
      series: [
        { label: "t (s)", value: function (u, v) { return v == null ? "-" : v.toFixed(2); } },
        { label: "wheel rotation (Hz)", stroke: "rgba(255,255,255,0.9)", width: 1 },
        { label: "2 x wheel (Hz)", stroke: "rgba(255,255,255,0.6)", width: 1, dash: [3, 3] }
      ],
      axes: [xAxis(ride, true), { label: "frequency (Hz)", size: 62, labelSize: 18 }],
      hooks: { drawClear: [drawImage], setScale: [syncScales(state)] },
      plugins: [navigation(state)]
    };
    var div = document.createElement("div");
    div.className = "chart";
    div.dataset.channel = "spectrogram";
    holder.appendChild(div);
    var chart = new uPlot(opts, [ride.t, harmonic(1), harmonic(2)], div);
    state.charts.push(chart);
    image.onload = function () { chart.redraw(false); };
    image.src = "data:image/png;base64," + spec.png_base64;
  }

  function buildRide(k) {
    if (built[k]) return built[k];
    var ride = rides[k];
    var view = document.getElementById("view-ride-" + k);
    var t = ride.t;
    var state = {
      key: "ride-" + k,
      charts: [],
      span: [t.length ? t[0] : 0, t.length ? t[t.length - 1] : 1],
      syncing: false
    };
    var charts = view.querySelector(".charts");
    for (var c = 0; c < FIGURE6; c++) {
      signalChart(ride, state, c, c === FIGURE6 - 1, charts);
    }
    spectrogramChart(ride, state, view.querySelector(".spectrogram"));
    view.querySelectorAll(".controls [data-act]").forEach(function (el) {
      var act = el.dataset.act;
      el.addEventListener(act === "imu" ? "change" : "click", function () {
        var x = state.charts[0].scales.x, w = x.max - x.min;
        if (act === "out") zoomTo(state, x.min - w / 2, x.max + w / 2);
        if (act === "left") zoomTo(state, x.min - w / 3, x.max - w / 3);
        if (act === "right") zoomTo(state, x.min + w / 3, x.max + w / 3);
        if (act === "all") zoomTo(state, state.span[0], state.span[1]);
        if (act === "imu") showImu(ride, state, view, el.checked);
      });
    });
    view.querySelectorAll(".events tr[data-t]").forEach(function (row) {
      function go() {
        var a = parseFloat(row.dataset.t), b = parseFloat(row.dataset.end);
        var pad = Math.max(2, (b - a) * 0.3);
        zoomTo(state, a - pad, b + pad);
      }
      row.addEventListener("click", go);
      row.addEventListener("keydown", function (e) { if (e.key === "Enter") go(); });
    });
    built[k] = state;
    return state;
  }

  function showImu(ride, state, view, on) {
    var holder = view.querySelector(".imu-charts");
    if (on && !holder.childElementCount) {
      var x = state.charts[0].scales.x;
      for (var c = FIGURE6; c < ride.channels.length; c++) {
        signalChart(ride, state, c, false, holder).setScale("x", { min: x.min, max: x.max });
      }
    }
    holder.hidden = !on;
  }

  // Shows the view named `name` (the page's fragment: `campaign`,
  // `ride-0`, ...); the views' ids differ from their names, so choosing
  // one never scrolls the page to it.
  function show(name) {
    var views = document.querySelectorAll("main.view");
    var target = document.getElementById("view-" + name) || views[0];
    views.forEach(function (v) { v.hidden = v !== target; });
    document.querySelectorAll("nav a").forEach(function (a) {
      a.classList.toggle("current", a.getAttribute("href") === "#" + target.dataset.view);
    });
    if (target.dataset.ride !== undefined) buildRide(+target.dataset.ride);
    return target;
  }

  window.addEventListener("resize", function () {
    Object.keys(built).forEach(function (k) {
      built[k].charts.forEach(function (c) {
        var w = c.root.parentNode.clientWidth;
        if (w && w !== c.width) c.setSize({ width: w, height: c.height });
      });
    });
  });
  window.addEventListener("hashchange", function () { show(location.hash.substring(1)); });

  // The page's own check, for tests in a headless browser: every view
  // built, its sections present, a zoom step timed (to the end of the
  // redraw uPlot queues), any error caught.
  function tick() {
    return new Promise(function (resolve) { setTimeout(resolve, 0); });
  }
  async function selfTest() {
    var result = { views: [], errors: errors };
    var t0 = performance.now();
    var views = document.querySelectorAll("main.view");
    for (var i = 0; i < views.length; i++) {
      var view = views[i];
      var t1 = performance.now();
      show(view.dataset.view);
      await Promise.resolve();
      var entry = {
        id: view.dataset.view,
        build_ms: performance.now() - t1,
        sections: Array.prototype.map.call(view.querySelectorAll("[data-section]"), function (s) {
          return s.dataset.section + (s.textContent.trim() || s.querySelector("svg, canvas") ? "" : ":empty");
        }),
        events: view.querySelectorAll(".events tr[data-t]").length
      };
      var state = built[view.dataset.ride];
      if (state) {
        await tick();
        var rows = view.querySelectorAll(".events tr[data-t]");
        var t2 = performance.now();
        if (rows.length) rows[rows.length - 1].click(); else zoomTo(state, state.span[0], state.span[0] + 1);
        await Promise.resolve();
        entry.zoom_ms = performance.now() - t2;
        await tick();
        var x = state.charts[0].scales.x;
        entry.zoomed = [x.min, x.max];
        entry.synced = state.charts.every(function (c) {
          return c.scales.x.min === x.min && c.scales.x.max === x.max;
        });
        var imu = view.querySelector("[data-act=imu]");
        imu.checked = true;
        imu.dispatchEvent(new Event("change"));
        await tick();
        entry.charts = state.charts.length;
        entry.canvases = view.querySelectorAll("canvas").length;
      } else {
        var answer = document.getElementById("wobble-speed");
        entry.wobble_speed_text = answer ? answer.textContent : null;
      }
      result.views.push(entry);
    }
    result.total_ms = performance.now() - t0;
    // A link of the page (the runs table's first) chooses its view.
    document.querySelector("table.runs a").click();
    await tick();
    var shown = document.querySelector("main.view:not([hidden])");
    result.link_shows = shown ? shown.dataset.view : null;
    show("campaign");
    document.getElementById("selftest").textContent = JSON.stringify(result);
  }

  var start = performance.now();
  show(location.hash.substring(1));
  if (location.hash === "#selftest") {
    selfTest().catch(function (e) { errors.push(String(e)); });
  }
  document.body.dataset.firstRenderMs = (performance.now() - start).toFixed(1);
})();
