// What the head is told: the drawing from the front and the side, the
// three angles, the pulses and the plot of the last seconds, from
// telemetry (or from `status` when the firmware streams none).

const $ = (id) => document.getElementById(id);
/** The plot's window, in seconds. */
const WINDOW_S = 10;

const plotData = [[], [], [], []];
let plot = null;
let plotDirty = false;

export function makePlot() {
  const el = $('plot');
  plot = new uPlot(
    {
      width: el.clientWidth || 370,
      height: 120,
      legend: { show: false },
      scales: { x: { time: false } },
      axes: [{ label: 's', size: 30 }, { label: '°', size: 40 }],
      series: [
        { label: 't' },
        { label: 'pitch', stroke: '#d6451d', width: 1.5 },
        { label: 'roll', stroke: '#1d9b55', width: 1.5 },
        { label: 'yaw', stroke: '#1d6fd6', width: 1.5 },
      ],
    },
    plotData,
    el,
  );
  setInterval(() => {
    if (plotDirty) {
      plot.setData(plotData);
      plotDirty = false;
    }
  }, 100);
}

export function showTelemetry(t) {
  showPose(t.pitch, t.roll, t.yaw);
  $('pulses').textContent = `pulses ${t.us.join(', ')} µs · t ${(t.t / 1000).toFixed(2)} s` + (t.lost ? ` · ${t.lost} lines lost` : '');
  const s = t.t / 1000;
  plotData[0].push(s);
  plotData[1].push(t.pitch);
  plotData[2].push(t.roll);
  plotData[3].push(t.yaw);
  while (plotData[0].length && plotData[0][0] < s - WINDOW_S) for (const series of plotData) series.shift();
  plotDirty = true;
}

export function showPose(pitch, roll, yaw) {
  $('pitch').textContent = pitch.toFixed(1);
  $('roll').textContent = roll.toFixed(1);
  $('yaw').textContent = yaw.toFixed(1);
  // Front: roll tilts the head; yaw turns the face sideways.
  $('front-head').setAttribute('transform', `rotate(${-roll})`);
  const shift = 28 * Math.sin((yaw * Math.PI) / 180);
  $('front-face').setAttribute('transform', `translate(${shift} 0)`);
  // Side, from the head's right (its face to the right): pitch nods the
  // head, positive nose down (clockwise on the page).
  $('side-head').setAttribute('transform', `rotate(${pitch})`);
}
