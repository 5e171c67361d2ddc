use std::time::Instant;

fn decode(data: &[u8]) -> Result<(u32, u32, Vec<Vec<i32>>), String> {
    #[cfg(any(feature = "openjp2", feature = "csys"))]
    {
        let img = jpeg2k::Image::from_bytes(data).map_err(|e| e.to_string())?;
        let comps = img.components();
        let w = img.width();
        let h = img.height();
        return Ok((w, h, comps.iter().map(|c| c.data().to_vec()).collect()));
    }
    #[cfg(feature = "hayro")]
    {
        use hayro_jpeg2000::{DecodeSettings, DecoderContext, Image};
        let s = DecodeSettings { resolve_palette_indices: false, strict: false, target_resolution: None };
        let img = Image::new(data, &s).map_err(|e| format!("{e:?}"))?;
        let (w, h) = (img.width(), img.height());
        if (w as u64) * (h as u64) > 1 << 26 { return Err(format!("header says {w} x {h}")); }
        let mut ctx = DecoderContext::default();
        let dec = img.decode(&mut ctx).map_err(|e| format!("{e:?}"))?;
        let signed: Vec<(bool, u8)> = siz(data);
        return Ok((w, h, dec.components().iter().enumerate().map(|(i, c)| { let (sg, p) = signed.get(i).copied().unwrap_or((false, 8)); let off = if sg { 1i32 << (p - 1) } else { 0 }; c.samples().iter().map(|v| v.round() as i32 - off).collect() }).collect()));
    }
}

fn main() {
    let dir = std::env::args().nth(1).unwrap();
    let reps: usize = std::env::args().nth(2).map(|s| s.parse().unwrap()).unwrap_or(1);
    let mut files: Vec<_> = std::fs::read_dir(&dir).unwrap().flatten().map(|e| e.path()).filter(|p| p.extension().is_some_and(|e| e == "j2k")).collect();
    files.sort();
    let data: Vec<Vec<u8>> = files.iter().map(|f| std::fs::read(f).unwrap()).collect();
    let (mut ok, mut bad, mut mismatch) = (0, 0, 0);
    for (f, d) in files.iter().zip(&data) {
        match decode(d) {
            Ok((w, h, comps)) => {
                let raw = f.with_extension("raw");
                if let Ok(r) = std::fs::read(&raw) {
                    let n = (w * h) as usize;
                    let bps = r.len() / (n * comps.len()).max(1);
                    let mut same = true;
                    'o: for i in 0..n { for (c, comp) in comps.iter().enumerate() {
                        let k = (i * comps.len() + c) * bps;
                        let v: i64 = match bps { 1 => r[k] as i64, 2 => i16::from_le_bytes([r[k], r[k+1]]) as i64, _ => 0 };
                        let got = comp.get(i).copied().unwrap_or(i32::MIN) as i64;
                        let ok_ = got == v || (bps == 2 && (got as u16 as i16 as i64) == v) || (bps == 1 && got == (v as u8) as i64);
                        if !ok_ && std::env::var("COUNT").is_ok() { let mut nd=0; let mut mx=0i64; for i in 0..n { let k=(i*comps.len())*bps; let v: i64 = if bps==2 { i16::from_le_bytes([r[k],r[k+1]]) as i64 } else { r[k] as i64 }; let g = comps[0][i] as i64; if g!=v { nd+=1; mx = mx.max((g-v).abs()); } } eprintln!("{}: {nd} of {n} differ, max {mx}", f.display()); }
                        if !ok_ { if mismatch < 5 { eprintln!("{}: pixel {i} comp {c}: got {got} want {v}", f.display()); } same = false; break 'o; }
                    }}
                    if !same { mismatch += 1 } else { ok += 1 }
                } else { ok += 1 }
            }
            Err(e) => { bad += 1; eprintln!("{}: {e}", f.display()); }
        }
    }
    let t = Instant::now();
    for _ in 0..reps { for d in &data { let _ = std::hint::black_box(decode(d)); } }
    let el = t.elapsed().as_secs_f64();
    println!("{} streams: ok {ok} mismatch {mismatch} failed {bad}; {reps} passes {:.3} s, {:.2} ms/stream", data.len(), el, el * 1e3 / (reps * data.len()) as f64);
}

#[allow(dead_code)]
fn siz(d: &[u8]) -> Vec<(bool, u8)> {
    let mut i = 0;
    while i + 4 < d.len() { if d[i] == 0xFF && d[i+1] == 0x51 { break; } i += 1; }
    let base = i + 4; // after marker + Lsiz
    let c = u16::from_be_bytes([d[base + 34], d[base + 35]]) as usize;
    (0..c).map(|k| { let s = d[base + 36 + 3 * k]; (s & 0x80 != 0, (s & 0x7F) + 1) }).collect()
}
