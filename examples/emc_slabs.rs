//! What `emc`'s slabs cost and buy on a mesh: its stream without slabs and with 2, 4, 8 and 16
//! (passes of 2^13 visits or more sliced, as `emc` writes large meshes), each stream's bytes and
//! its decode time on one thread and on all (best of N), as one JSON line per slab count.
//! Run: cargo run --release --example emc_slabs -- MESH [N] (a path, or a name under ../shared/meshes)
//! With `--write OUT.mc SLABS LOG2` it writes one stream sliced into SLABS slabs for passes of
//! 2^LOG2 visits or more instead (the fuzz seeds' sliced streams, from small meshes), with
//! `AHEAD` an `emc-ahead` stream taking cells that many levels ahead.
use meshcodec::codecs::emc::modelled::{encode_sliced, encode_sliced_ahead};
use meshcodec::codecs::emc::SLICED_VISITS_LOG2;
use meshcodec::codecs::{self, EncodeOptions, Stop};
use std::time::Instant;

type Failure = Box<dyn std::error::Error>;

fn main() -> Result<(), Failure> {
    let args: Vec<String> = std::env::args().collect();
    let Some(path) = args.get(1) else {
        return Err(
            "usage: emc_slabs MESH [N] | emc_slabs MESH --write OUT.mc SLABS LOG2 [AHEAD]".into(),
        );
    };
    let mesh = meshcodec::mesh::io::read_mesh(&meshcodec::mesh::io::resolve(path)?)?;
    let options = EncodeOptions {
        quant_bits: 12,
        ..codecs::by_name("emc")?.default_options()
    };
    let canonical = codecs::canonical_for(&mesh, &options)?;
    if args.get(2).map(String::as_str) == Some("--write") {
        let (Some(out), Some(slabs), Some(log2)) = (args.get(3), args.get(4), args.get(5)) else {
            return Err("usage: emc_slabs MESH --write OUT.mc SLABS LOG2 [AHEAD]".into());
        };
        // An optional lookahead: the stream is emc-ahead's.
        let ahead = args.get(6).map_or(Ok(0), |k| k.parse())?;
        let encoded = encode_sliced_ahead(&canonical, ahead, slabs.parse()?, log2.parse()?)?;
        std::fs::write(out, &encoded.bytes)?;
        return Ok(());
    }
    let repeats: usize = args.get(2).map_or(Ok(3), |n| n.parse())?;
    let one_thread = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    let best = |bytes: &[u8], pool: Option<&rayon::ThreadPool>| -> Result<f64, Failure> {
        let mut best = f64::INFINITY;
        for _ in 0..repeats {
            let started = Instant::now();
            let decoded = match pool {
                Some(pool) => pool.install(|| codecs::decode(bytes, Stop::All))?,
                None => codecs::decode(bytes, Stop::All)?,
            };
            best = best.min(started.elapsed().as_secs_f64());
            if canonical.check_lossless(&decoded.0.mesh).is_err() {
                return Err("a decode is not lossless".into());
            }
        }
        Ok(best)
    };
    let mut unsliced = 0;
    for slabs in [1u8, 2, 4, 8, 16] {
        let bytes = encode_sliced(&canonical, slabs, SLICED_VISITS_LOG2)?.bytes;
        if slabs == 1 {
            unsliced = bytes.len();
        }
        let (alone, all) = (best(&bytes, Some(&one_thread))?, best(&bytes, None)?);
        println!(
            "{{\"slabs\": {slabs}, \"bytes\": {}, \"over_unsliced\": {:.5}, \"decode_one_thread\": {alone:.4}, \"decode_all_threads\": {all:.4}, \"threads\": {}}}",
            bytes.len(),
            bytes.len() as f64 / unsliced as f64 - 1.0,
            rayon::current_num_threads()
        );
    }
    Ok(())
}
