// The monomap report page: draws everything from the JSON in
// <script id="report-data"> (see src/monomap/report/report_data.h) with
// three.js (3D view) and Chart.js (charts). It also records, as data
// attributes of <body>, what scripts/check_report.sh checks in headless
// Chromium: JavaScript and console errors, images decoded, charts with
// data, and the non-background pixels of the WebGL view.
'use strict';

(function () {
  const body = document.body;
  const status = { errors: 0, consoleErrors: 0, imagesTotal: 0,
                   imagesDecoded: 0, charts: 0, chartsEmpty: 0 };
  function publish() {
    body.dataset.jsErrors = String(status.errors);
    body.dataset.consoleErrors = String(status.consoleErrors);
    body.dataset.imagesTotal = String(status.imagesTotal);
    body.dataset.imagesDecoded = String(status.imagesDecoded);
    body.dataset.charts = String(status.charts);
    body.dataset.chartsEmpty = String(status.chartsEmpty);
  }
  window.addEventListener('error', function () { status.errors++; publish(); });
  window.addEventListener('unhandledrejection',
                          function () { status.errors++; publish(); });
  const consoleError = console.error.bind(console);
  console.error = function () {
    status.consoleErrors++;
    publish();
    consoleError.apply(null, arguments);
  };

  const data = JSON.parse(document.getElementById('report-data').textContent);

  // ---------------------------------------------------------------- helpers
  function el(tag, attrs, children) {
    const e = document.createElement(tag);
    for (const k in attrs || {}) {
      if (k === 'text') e.textContent = attrs[k];
      else if (k === 'class') e.className = attrs[k];
      else e.setAttribute(k, attrs[k]);
    }
    for (const c of children || []) e.appendChild(c);
    return e;
  }
  function show(id) { document.getElementById(id).hidden = false; }
  function fmt(v, digits) {
    return (typeof v === 'number' && isFinite(v)) ? v.toFixed(digits) : '-';
  }
  // A distinct colour per plane id (golden-ratio hue steps); grey for -1.
  function planeColor(id) {
    if (id < 0) return new THREE.Color(0.62, 0.62, 0.62);
    const c = new THREE.Color();
    c.setHSL((id * 0.61803398875 + 0.05) % 1, 0.8, 0.5);
    return c;
  }
  function cssColor(c) { return '#' + c.getHexString(); }
  const seriesColors = ['#1f77b4', '#d62728', '#2ca02c', '#9467bd', '#ff7f0e',
                        '#8c564b', '#e377c2', '#17becf'];
  function seriesColor(name, i) {
    if (name === 'ground truth') return '#000000';
    return seriesColors[i % seriesColors.length];
  }
  function imageFromBase64(mime, b64, onload) {
    const img = new Image();
    status.imagesTotal++;
    img.onload = function () {
      status.imagesDecoded++;
      publish();
      if (onload) onload(img);
    };
    img.onerror = function () {
      console.error('report: an embedded image does not decode');
    };
    img.src = 'data:' + mime + ';base64,' + b64;
    return img;
  }
  function stats(values) {
    const v = values.slice().sort(function (a, b) { return a - b; });
    const n = v.length;
    if (n === 0) return null;
    let sum = 0, sq = 0;
    for (const x of v) { sum += x; sq += x * x; }
    const mean = sum / n;
    const median = n % 2 ? v[(n - 1) / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
    return { count: n, rmse: Math.sqrt(sq / n), mean: mean, median: median,
             std: Math.sqrt(Math.max(0, sq / n - mean * mean)),
             min: v[0], max: v[n - 1] };
  }

  // ----------------------------------------------------------------- charts
  Chart.defaults.animation = false;
  Chart.defaults.font.size = 12;
  function chart(id, config) {
    const c = new Chart(document.getElementById(id), config);
    let points = 0;
    for (const d of c.data.datasets) points += d.data.length;
    status.charts++;
    if (points === 0) status.chartsEmpty++;
    publish();
    return c;
  }
  function axis(title, extra) {
    return Object.assign({ type: 'linear', title: { display: true, text: title } },
                         extra || {});
  }
  function lineSet(label, points, color, extra) {
    return Object.assign({ label: label, data: points, showLine: true,
                           pointRadius: 0, borderWidth: 1.5,
                           borderColor: color, backgroundColor: color },
                         extra || {});
  }
  // Sets the axis ranges so that one metre is as long on x as on y.
  function equalAxes(c, xs, ys) {
    const area = c.chartArea;
    let x0 = Math.min.apply(null, xs), x1 = Math.max.apply(null, xs);
    let y0 = Math.min.apply(null, ys), y1 = Math.max.apply(null, ys);
    const w = area.right - area.left, h = area.bottom - area.top;
    const perPx = 1.05 * Math.max((x1 - x0) / w, (y1 - y0) / h, 1e-6);
    const cx = 0.5 * (x0 + x1), cy = 0.5 * (y0 + y1);
    c.options.scales.x.min = cx - 0.5 * w * perPx;
    c.options.scales.x.max = cx + 0.5 * w * perPx;
    c.options.scales.y.min = cy - 0.5 * h * perPx;
    c.options.scales.y.max = cy + 0.5 * h * perPx;
    c.update('none');
  }
  function cdfPoints(values) {
    const v = values.slice().sort(function (a, b) { return a - b; });
    return v.map(function (x, i) { return { x: x, y: (i + 1) / v.length }; });
  }
  function histogram(seriesList, scale) {
    let max = 0;
    for (const s of seriesList) for (const e of s.values) max = Math.max(max, e * scale);
    const bins = 20, width = max > 0 ? max / bins : 1;
    const labels = [];
    for (let b = 0; b < bins; b++) labels.push(fmt((b + 0.5) * width, 1));
    const datasets = seriesList.map(function (s, i) {
      const counts = new Array(bins).fill(0);
      for (const e of s.values) counts[Math.min(bins - 1, Math.floor(e * scale / width))]++;
      return { label: s.name, data: counts, backgroundColor: seriesColor(s.name, i) };
    });
    return { labels: labels, datasets: datasets };
  }
  function statsTable(table, rows, unit, scale) {
    table.appendChild(el('tr', {}, ['', 'count', 'rmse', 'mean', 'median', 'std',
                                    'min', 'max'].map(function (h, i) {
      return el('th', { text: i >= 2 ? h + ' (' + unit + ')' : h });
    })));
    for (const r of rows) {
      const s = stats(r.values);
      if (!s) continue;
      const cells = [r.name, String(s.count)];
      for (const k of ['rmse', 'mean', 'median', 'std', 'min', 'max']) {
        cells.push(fmt(s[k] * scale, 1));
      }
      table.appendChild(el('tr', {}, cells.map(function (t) {
        return el('td', { text: t });
      })));
    }
  }
  // Error over time, CDF and histogram of several series (evo style).
  function errorCharts(series, ids) {
    const t0 = Math.min.apply(null, series.map(function (s) { return s.t[0]; }));
    chart(ids[0], { type: 'scatter', data: { datasets: series.map(function (s, i) {
      return lineSet(s.name, s.t.map(function (t, k) {
        return { x: t - t0, y: 100 * s.values[k] };
      }), seriesColor(s.name, i));
    }) }, options: { scales: { x: axis('time (s)'), y: axis('position error (cm)') },
      plugins: { title: { display: true, text: 'Error over time' } } } });
    chart(ids[1], { type: 'scatter', data: { datasets: series.map(function (s, i) {
      return lineSet(s.name, cdfPoints(s.values).map(function (p) {
        return { x: 100 * p.x, y: p.y };
      }), seriesColor(s.name, i), { stepped: true });
    }) }, options: { scales: { x: axis('position error (cm)'),
                                y: axis('fraction of poses', { min: 0, max: 1 }) },
      plugins: { title: { display: true, text: 'Cumulative distribution' } } } });
    chart(ids[2], { type: 'bar', data: histogram(series, 100), options: {
      scales: { x: { title: { display: true, text: 'position error (cm)' } },
                y: axis('poses') },
      plugins: { title: { display: true, text: 'Histogram' } } } });
  }

  // ------------------------------------------------------- header sections
  function header() {
    document.title = data.title;
    document.getElementById('title').textContent = data.title;
    const p = data.provenance || {};
    document.getElementById('subtitle').textContent =
        'monomap ' + p.version + ' (commit ' + p.commit + '), generated ' +
        p.generated_utc;
    const cards = document.getElementById('cards');
    function card(label, value) {
      cards.appendChild(el('div', { class: 'card', text: label }, [el('b', { text: value })]));
    }
    const s = data.summary || {};
    card('frames', String(s.frames));
    card('landmarks', String(s.landmarks));
    card('planes', String(s.planes));
    card('tracks', String(s.tracks));
    for (const e of (data.errors || {}).series || []) {
      const st = stats(e.error_m);
      if (st) card('ATE ' + e.name + ' (rmse)', fmt(100 * st.rmse, 1) + ' cm');
    }
    for (const r of data.localization || []) {
      if (r.error && r.error.error_m.length) {
        const last = r.error.error_m[r.error.error_m.length - 1];
        card(r.name + ': final error', fmt(100 * last, 1) + ' cm');
      }
    }
    if ((data.problems || []).length) card('input problems', String(data.problems.length));
    const problems = document.getElementById('problems');
    for (const pr of data.problems || []) {
      problems.appendChild(el('li', { text: pr.file + ': ' + pr.message }));
    }
    if ((data.problems || []).length) show('problems-section');
  }
  function toc() {
    const nav = document.getElementById('toc');
    for (const s of document.querySelectorAll('section[data-title]')) {
      if (s.hidden) continue;
      nav.appendChild(el('a', { href: '#' + s.id, text: s.dataset.title }));
    }
  }

  // ---------------------------------------------------------------- 3D view
  function view3d() {
    const container = document.getElementById('view3d');
    const message = document.getElementById('view3d-message');
    const width = container.clientWidth, height = container.clientHeight;
    let renderer;
    try {
      renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    } catch (e) {
      message.textContent = 'WebGL is not available in this browser: ' + e.message;
      body.dataset.webgl = 'unavailable';
      return;
    }
    const background = 0x1e2228;
    renderer.setClearColor(background);
    renderer.setPixelRatio(1);
    renderer.setSize(width, height);
    container.appendChild(renderer.domElement);
    const scene = new THREE.Scene();
    const camera = new THREE.PerspectiveCamera(50, width / height, 0.01, 1000);
    camera.up.set(0, 0, 1);  // the map's world frame has z up
    const controls = new THREE.OrbitControls(camera, renderer.domElement);
    const layers = {};
    const box = new THREE.Box3();

    function addLayer(name, object, visible) {
      layers[name] = object;
      object.visible = visible !== false;
      scene.add(object);
      const box_ = el('input', { type: 'checkbox' });
      box_.checked = object.visible;
      box_.addEventListener('change', function () { object.visible = box_.checked; });
      document.getElementById('layer-controls').appendChild(
          el('label', {}, [box_, document.createTextNode(' ' + name)]));
    }
    function polyline(xyz, color) {
      const g = new THREE.BufferGeometry();
      g.setAttribute('position', new THREE.Float32BufferAttribute(xyz, 3));
      return new THREE.Line(g, new THREE.LineBasicMaterial({ color: color }));
    }

    // Points coloured by plane; the view is framed on the central 98 % of
    // them so that a few far outliers do not shrink the map to a dot.
    const pts = data.points || { xyz: [], plane: [] };
    if (pts.plane.length) {
      const colors = [];
      for (const id of pts.plane) { const c = planeColor(id); colors.push(c.r, c.g, c.b); }
      const g = new THREE.BufferGeometry();
      g.setAttribute('position', new THREE.Float32BufferAttribute(pts.xyz, 3));
      g.setAttribute('color', new THREE.Float32BufferAttribute(colors, 3));
      addLayer('points', new THREE.Points(g, new THREE.PointsMaterial({
        size: 3, sizeAttenuation: false, vertexColors: THREE.VertexColors })));
      for (let k = 0; k < 3; k++) {
        const v = [];
        for (let i = k; i < pts.xyz.length; i += 3) v.push(pts.xyz[i]);
        v.sort(function (a, b) { return a - b; });
        box.min.setComponent(k, v[Math.floor(0.01 * (v.length - 1))]);
        box.max.setComponent(k, v[Math.floor(0.99 * (v.length - 1))]);
      }
    }
    const group = new THREE.Group();
    (data.trajectories || []).forEach(function (t, i) {
      if (!t.xyz.length) return;
      const line = polyline(t.xyz, t.name === 'ground truth' ? 0xffffff
                                   : new THREE.Color(seriesColor(t.name, i)));
      line.name = t.name;
      group.add(line);
      for (let k = 0; k < t.xyz.length; k += 3) {
        box.expandByPoint(new THREE.Vector3(t.xyz[k], t.xyz[k + 1], t.xyz[k + 2]));
      }
    });
    if (group.children.length) addLayer('camera paths', group);

    const legend = document.getElementById('plane-legend');
    for (const p of data.planes || []) {
      legend.appendChild(el('span', {}, [
        el('span', { class: 'swatch', style: 'background:' + cssColor(planeColor(p.id)) }),
        document.createTextNode('plane ' + p.id)]));
    }
    legend.appendChild(el('span', {}, [
      el('span', { class: 'swatch', style: 'background:' + cssColor(planeColor(-1)) }),
      document.createTextNode('no plane')]));
    (data.trajectories || []).forEach(function (t, i) {
      legend.appendChild(el('span', {}, [
        el('span', { class: 'swatch', style: 'background:' +
          (t.name === 'ground truth' ? '#ffffff;border:1px solid #999' : seriesColor(t.name, i)) }),
        document.createTextNode(t.name)]));
    });

    const particles = particleLayer(scene, addLayer, box);

    if (box.isEmpty()) box.set(new THREE.Vector3(-1, -1, -1), new THREE.Vector3(1, 1, 1));
    const center = box.getCenter(new THREE.Vector3());
    const size = Math.max(box.getSize(new THREE.Vector3()).length(), 0.5);
    camera.position.set(center.x - 0.3 * size, center.y - 0.6 * size,
                        center.z + 0.45 * size);
    camera.near = size / 1000;
    camera.far = size * 100;
    camera.updateProjectionMatrix();
    controls.target.copy(center);
    controls.update();

    function render() { renderer.render(scene, camera); }
    controls.addEventListener('change', render);
    if (particles) particles.onChange = render;

    // Counts the pixels that differ from the background: the check's
    // evidence that the view shows the map.
    function measure() {
      const gl = renderer.getContext();
      const w = gl.drawingBufferWidth, h = gl.drawingBufferHeight;
      const px = new Uint8Array(w * h * 4);
      gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, px);
      const bg = new THREE.Color(background);
      const r0 = Math.round(bg.r * 255), g0 = Math.round(bg.g * 255), b0 = Math.round(bg.b * 255);
      let other = 0;
      for (let i = 0; i < px.length; i += 4) {
        if (Math.abs(px[i] - r0) + Math.abs(px[i + 1] - g0) + Math.abs(px[i + 2] - b0) > 12) other++;
      }
      body.dataset.webglPixels = String(w * h);
      body.dataset.webglNonBackground = String(other);
    }
    function finish(note) {
      if (note) message.textContent = note;
      render();
      measure();
      body.dataset.webgl = 'ready';
      body.dataset.reportReady = '1';
    }
    if (!data.glb_base64) {
      finish('map.glb could not be read: no textured planes.');
      return;
    }
    const bytes = Uint8Array.from(atob(data.glb_base64), function (c) { return c.charCodeAt(0); });
    new THREE.GLTFLoader().parse(bytes.buffer, '', function (gltf) {
      // Unlit: the textures are what the camera saw, not a surface to shade.
      gltf.scene.traverse(function (o) {
        if (!o.isMesh) return;
        const old = o.material;
        o.material = new THREE.MeshBasicMaterial({ map: old.map, side: THREE.DoubleSide,
                                                   alphaTest: 0.5 });
      });
      addLayer('textured planes', gltf.scene);
      finish('');
    }, function (error) {
      finish('map.glb could not be shown: ' + error);
    });
  }

  // Particles of the localization runs, one step at a time.
  function particleLayer(scene, addLayer, box) {
    const runs = (data.localization || []).filter(function (r) {
      return r.particles && r.particles.xyz.length;
    });
    const estimates = new THREE.Group();
    (data.localization || []).forEach(function (r, i) {
      if (!r.xyz.length) return;
      const line = new THREE.Line(new THREE.BufferGeometry(), new THREE.LineBasicMaterial({
        color: new THREE.Color(seriesColors[(i + 2) % seriesColors.length]) }));
      line.geometry.setAttribute('position', new THREE.Float32BufferAttribute(r.xyz, 3));
      estimates.add(line);
      if (r.groundtruth) {
        const g = new THREE.BufferGeometry();
        g.setAttribute('position', new THREE.Float32BufferAttribute(r.groundtruth.xyz, 3));
        estimates.add(new THREE.Line(g, new THREE.LineBasicMaterial({ color: 0xffffff })));
      }
    });
    if (estimates.children.length) addLayer('localization estimates', estimates);
    if (!runs.length) return null;
    const geometry = new THREE.BufferGeometry();
    const maxCount = Math.max.apply(null, runs.map(function (r) {
      return Math.max.apply(null, r.particles.xyz.map(function (s) { return s.length; }));
    }));
    geometry.setAttribute('position', new THREE.Float32BufferAttribute(new Float32Array(maxCount), 3));
    const cloud = new THREE.Points(geometry, new THREE.PointsMaterial({
      color: 0xffd400, size: 3, sizeAttenuation: false }));
    const truth = new THREE.Mesh(new THREE.SphereGeometry(1, 12, 8),
                                 new THREE.MeshBasicMaterial({ color: 0x00e5ff }));
    const group = new THREE.Group();
    group.add(cloud);
    group.add(truth);
    addLayer('particles', group);
    // The view stays framed on the map (a global start spreads the first
    // particles over the whole area).
    truth.scale.setScalar(0.01 * Math.max(box.getSize(new THREE.Vector3()).length(), 0.5));

    const select = document.getElementById('run-select');
    runs.forEach(function (r, i) { select.appendChild(el('option', { value: i, text: r.name })); });
    const slider = document.getElementById('step-slider');
    const label = document.getElementById('step-label');
    const state = { run: 0, index: 0, timer: null, onChange: null };
    function setStep(index) {
      const r = runs[state.run];
      state.index = Math.max(0, Math.min(index, r.particles.xyz.length - 1));
      slider.max = String(r.particles.xyz.length - 1);
      slider.value = String(state.index);
      const xyz = r.particles.xyz[state.index];
      const pos = geometry.attributes.position;
      pos.array.set(xyz);
      pos.needsUpdate = true;
      geometry.setDrawRange(0, xyz.length / 3);
      geometry.computeBoundingSphere();
      const step = r.particles.steps[state.index];
      truth.visible = false;
      if (r.groundtruth && step < r.groundtruth.t.length) {
        const g = r.groundtruth.xyz;
        truth.position.set(g[3 * step], g[3 * step + 1], g[3 * step + 2]);
        truth.visible = true;
      }
      label.textContent = 'update ' + step + ' of ' + (r.t.length - 1) + ': ' +
          (xyz.length / 3) + ' particles shown' + (truth.visible ? ' (cyan: true pose)' : '');
      if (state.onChange) state.onChange();
    }
    slider.addEventListener('input', function () { setStep(Number(slider.value)); });
    select.addEventListener('change', function () { state.run = Number(select.value); setStep(0); });
    const play = document.getElementById('play-button');
    play.addEventListener('click', function () {
      if (state.timer) {
        clearInterval(state.timer);
        state.timer = null;
        play.textContent = 'Play';
        return;
      }
      play.textContent = 'Pause';
      if (state.index >= runs[state.run].particles.xyz.length - 1) setStep(0);
      state.timer = setInterval(function () {
        if (state.index >= runs[state.run].particles.xyz.length - 1) { play.click(); return; }
        setStep(state.index + 1);
      }, 120);
    });
    show('particle-controls');
    setStep(0);
    return state;
  }

  // ------------------------------------------------------------- 2D charts
  function trajectory() {
    const sets = [];
    const xs = [], ys = [];
    function add(name, xyz, color, dashed) {
      const points = [];
      for (let k = 0; k < xyz.length; k += 3) {
        points.push({ x: xyz[k], y: xyz[k + 1] });
        xs.push(xyz[k]);
        ys.push(xyz[k + 1]);
      }
      if (points.length) {
        sets.push(lineSet(name, points, color, dashed ? { borderDash: [5, 3] } : {}));
      }
    }
    (data.trajectories || []).forEach(function (t, i) {
      add(t.name, t.xyz, seriesColor(t.name, i), t.name === 'odometry');
    });
    (data.localization || []).forEach(function (r, i) {
      add('localization: ' + r.name, r.xyz, seriesColors[(i + 2) % seriesColors.length], false);
    });
    if (!sets.length) return;
    show('trajectory-section');
    const dx = Math.max.apply(null, xs) - Math.min.apply(null, xs);
    const dy = Math.max.apply(null, ys) - Math.min.apply(null, ys);
    const c = chart('chart-trajectory', { type: 'scatter', data: { datasets: sets },
      options: { aspectRatio: Math.min(2.2, Math.max(0.8, dx / Math.max(dy, 1e-6))),
                 scales: { x: axis('x (m)'), y: axis('y (m)') } } });
    equalAxes(c, xs, ys);
    if (data.errors && data.errors.alignment) {
      document.getElementById('trajectory-note').textContent =
          'Top view (x-y), equal axes, in the map frame; the ground truth is ' +
          'aligned on the map\'s ' + data.errors.alignment + '.';
    }
  }

  function errors() {
    const series = ((data.errors || {}).series || []).filter(function (s) {
      return s.error_m.length;
    }).map(function (s) { return { name: s.name, t: s.t, values: s.error_m }; });
    if (!series.length) return;
    show('errors-section');
    document.getElementById('errors-note').textContent =
        'Position error per frame against the dataset\'s ground truth after aligning the ' +
        data.errors.alignment + ' (absolute trajectory error).';
    statsTable(document.getElementById('errors-table'), series, 'cm', 100);
    errorCharts(series, ['chart-error-time', 'chart-error-cdf', 'chart-error-hist']);
  }

  function localization() {
    const runs = data.localization || [];
    if (!runs.length) return;
    show('localization-section');
    const series = runs.filter(function (r) { return r.error && r.error.error_m.length; })
        .map(function (r) { return { name: r.name, t: r.error.t, values: r.error.error_m }; });
    const table = document.getElementById('localization-table');
    if (series.length) {
      statsTable(table, series, 'cm', 100);
      chart('chart-loc-error', { type: 'scatter', data: { datasets: series.map(function (s, i) {
        return lineSet(s.name, s.values.map(function (v, k) {
          return { x: k, y: Math.min(100, 100 * v) };
        }), seriesColor(s.name, i));
      }) }, options: { scales: { x: axis('update'), y: axis('position error (cm, capped at 100)') },
        plugins: { title: { display: true, text: 'Error per update' } } } });
      chart('chart-loc-cdf', { type: 'scatter', data: { datasets: series.map(function (s, i) {
        return lineSet(s.name, cdfPoints(s.values).map(function (p) {
          return { x: 100 * p.x, y: p.y };
        }), seriesColor(s.name, i), { stepped: true });
      }) }, options: { scales: { x: axis('position error (cm)', { type: 'logarithmic' }),
                                  y: axis('fraction of updates', { min: 0, max: 1 }) },
        plugins: { title: { display: true, text: 'Cumulative distribution' } } } });
    } else {
      table.appendChild(el('tr', {}, [el('td', { text: 'No ground truth for these runs.' })]));
    }
    const counts = runs.filter(function (r) {
      return r.report && r.report.steps && r.report.steps.length;
    });
    if (counts.length) {
      chart('chart-loc-particles', { type: 'scatter', data: { datasets: counts.map(function (r, i) {
        return lineSet(r.name, r.report.steps.map(function (s, k) {
          return { x: k, y: s.particles };
        }), seriesColor(r.name, i));
      }) }, options: { scales: { x: axis('update'), y: axis('particles') },
        plugins: { title: { display: true, text: 'Particles alive per update' } } } });
    }
  }

  // ---------------------------------------------------------------- images
  function textures() {
    const planes = (data.planes || []).filter(function (p) { return p.png_base64; });
    if (!planes.length) return;
    show('textures-section');
    const box = document.getElementById('textures');
    for (const p of planes) {
      const img = imageFromBase64('image/png', p.png_base64);
      img.className = 'tex';
      img.alt = 'texture of plane ' + p.id;
      box.appendChild(el('figure', {}, [img, el('figcaption', {}, [
        el('span', { class: 'swatch', style: 'background:' + cssColor(planeColor(p.id)) }),
        document.createTextNode('Plane ' + p.id + ': ' + p.width + 'x' + p.height +
          ' texels at ' + fmt(p.pixels_per_meter, 0) + ' px/m, coverage ' +
          fmt(100 * p.coverage, 0) + ' %, ' + p.points + ' points')])]));
    }
  }

  function features() {
    const frames = (data.features || {}).frames || [];
    if (!frames.length) return;
    show('features-section');
    document.getElementById('features-note').textContent =
        'Tracks seen in each frame with their last ' + frames[0].tail +
        ' frames (colour: track).';
    const box = document.getElementById('features');
    for (const f of frames) {
      const canvas = el('canvas', { width: f.width, height: f.height });
      canvas.style.maxWidth = '440px';
      imageFromBase64('image/jpeg', f.jpeg_base64, function (img) {
        const ctx = canvas.getContext('2d');
        ctx.drawImage(img, 0, 0);
        ctx.lineWidth = 1.5;
        f.tracks.forEach(function (t, i) {
          ctx.strokeStyle = 'hsl(' + Math.round((i * 137.508) % 360) + ',90%,55%)';
          ctx.beginPath();
          for (let k = 0; k < t.length; k += 2) {
            if (k === 0) ctx.moveTo(t[k], t[k + 1]); else ctx.lineTo(t[k], t[k + 1]);
          }
          ctx.stroke();
          ctx.beginPath();
          ctx.arc(t[t.length - 2], t[t.length - 1], 3, 0, 2 * Math.PI);
          ctx.stroke();
        });
      });
      box.appendChild(el('figure', {}, [canvas, el('figcaption', {
        text: 'Frame ' + f.frame + ' (t = ' + fmt(f.timestamp, 2) + ' s): ' +
              f.tracks.length + ' tracks' })]));
    }
  }

  // ------------------------------------------------- figures and provenance
  function valueText(v) {
    if (Array.isArray(v)) {
      if (v.every(function (x) { return typeof x !== 'object' || x === null; })) {
        return v.length > 12 ? '[' + v.length + ' values]' : v.join(', ');
      }
      return null;
    }
    if (typeof v === 'number') return Number.isInteger(v) ? String(v) : String(+v.toPrecision(5));
    if (typeof v === 'object' && v !== null) return null;
    return String(v);
  }
  // Nested JSON as nested key/value tables; arrays of objects as one table
  // with a column per key.
  function jsonTable(obj) {
    const table = el('table', { class: 'kv' });
    if (Array.isArray(obj)) {
      const keys = [];
      for (const row of obj) for (const k in row) if (keys.indexOf(k) < 0 && valueText(row[k]) !== null) keys.push(k);
      table.className = 'stats';
      table.appendChild(el('tr', {}, keys.map(function (k) { return el('th', { text: k }); })));
      for (const row of obj) {
        table.appendChild(el('tr', {}, keys.map(function (k) {
          return el('td', { text: k in row ? valueText(row[k]) : '' });
        })));
      }
      return table;
    }
    for (const k in obj) {
      const v = obj[k];
      const text = valueText(v);
      table.appendChild(el('tr', {}, [el('td', { text: k }),
        text !== null ? el('td', { text: text }) : el('td', {}, [jsonTable(v)])]));
    }
    return table;
  }
  function extra() {
    const e = data.extra;
    if (!e || typeof e !== 'object' || !Object.keys(e).length) return;
    show('extra-section');
    const box = document.getElementById('extra');
    for (const k in e) {
      box.appendChild(el('h3', { text: k }));
      const text = valueText(e[k]);
      box.appendChild(text !== null ? el('p', { text: text }) : jsonTable(e[k]));
    }
  }
  function provenance() {
    const p = data.provenance || {};
    const table = document.getElementById('provenance');
    const rows = [['command line', p.command_line], ['version', p.version],
                  ['commit', p.commit], ['generated', p.generated_utc],
                  ['map', p.inputs.map], ['dataset', p.inputs.dataset || '-']];
    for (const r of p.inputs.localization || []) {
      rows.push(['localization ' + r.name, r.sources.join(', ')]);
    }
    for (const r of rows) {
      table.appendChild(el('tr', {}, [el('td', { text: r[0] }),
        el('td', {}, [el('code', { text: r[1] || '' })])]));
    }
    const files = document.getElementById('map-files');
    files.appendChild(el('tr', {}, ['file', 'bytes', 'status', 'message'].map(function (h) {
      return el('th', { text: h });
    })));
    for (const f of data.map_files || []) {
      files.appendChild(el('tr', {}, [
        el('td', {}, [el('a', { href: f.link || f.path, text: f.name })]),
        el('td', { text: String(f.bytes) }),
        el('td', { class: f.status === 'ok' ? 'ok' : (f.message ? 'bad' : ''), text: f.status }),
        el('td', { text: f.message || '' })]));
    }
  }

  function run(name, f) {
    try {
      f();
    } catch (e) {
      console.error('report: ' + name + ': ' + (e && e.stack ? e.stack : e));
    }
  }
  publish();
  run('header', header);
  run('trajectory', trajectory);
  run('errors', errors);
  run('localization', localization);
  run('textures', textures);
  run('features', features);
  run('extra', extra);
  run('provenance', provenance);
  run('toc', toc);
  run('3D view', view3d);
  publish();
})();
