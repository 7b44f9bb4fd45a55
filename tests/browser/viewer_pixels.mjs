// What a <model-viewer> draws, measured in the page: a snapshot of its canvas (after two frames), the share of its
// pixels the model covers and how much their brightness varies (a head, shaded and textured, is not one flat
// colour). Runs in the browser: pass it to puppeteer's evaluate with the element, e.g. handle.evaluate(viewerPixels).
export async function viewerPixels(el) {
  await new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r)));
  const blob = await el.toBlob({ idealAspect: false });
  const bitmap = await createImageBitmap(blob);
  const canvas = document.createElement('canvas');
  canvas.width = bitmap.width;
  canvas.height = bitmap.height;
  const ctx = canvas.getContext('2d');
  ctx.drawImage(bitmap, 0, 0);
  const data = ctx.getImageData(0, 0, canvas.width, canvas.height).data;
  let covered = 0, sum = 0, sum2 = 0;
  for (let i = 0; i < data.length; i += 4) {
    if (data[i + 3] < 128) continue;
    covered += 1;
    const y = 0.299 * data[i] + 0.587 * data[i + 1] + 0.114 * data[i + 2];
    sum += y;
    sum2 += y * y;
  }
  const mean = covered ? sum / covered : 0;
  return { width: canvas.width, height: canvas.height, coveredFraction: covered / (data.length / 4),
           lumaStd: covered ? Math.sqrt(Math.max(0, sum2 / covered - mean * mean)) : 0 };
}
