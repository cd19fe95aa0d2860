//! `compare`: error metrics of an image against a reference (linear EXRs of the same size):
//! RMSE and relative RMSE on linear radiance, SSIM on the displayed luminance, FLIP of the
//! displayed images, mean ratio.
//! See `crate::metrics` for the definitions.

use std::path::PathBuf;

use anyhow::anyhow;
use clap::{Args, ValueEnum};

use crate::{export::read_exr, metrics, renderer::settings::Tonemap};

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum TonemapArg {
    Clamp,
    Reinhard,
    Aces,
}

impl TonemapArg {
    pub fn tonemap(self) -> Tonemap {
        match self {
            TonemapArg::Clamp => Tonemap::Clamp,
            TonemapArg::Reinhard => Tonemap::Reinhard,
            TonemapArg::Aces => Tonemap::Aces,
        }
    }
}

#[derive(Args, Debug)]
pub struct CompareArgs {
    /// The image to judge (linear EXR).
    pub image: PathBuf,
    /// The reference (linear EXR, same size), e.g. a ground truth's indirect.exr.
    pub reference: PathBuf,
    /// Exposure (EV) of the display transform SSIM looks through.
    #[arg(long, default_value_t = 0.0)]
    pub exposure: f32,
    #[arg(long, value_enum, default_value = "aces")]
    pub tonemap: TonemapArg,
    /// Also write the metrics as JSON here.
    #[arg(long)]
    pub json: Option<PathBuf>,
}

pub fn run(args: &CompareArgs) -> anyhow::Result<()> {
    let a = read_exr(&args.image).map_err(|e| anyhow!("{}: {e}", args.image.display()))?;
    let b = read_exr(&args.reference).map_err(|e| anyhow!("{}: {e}", args.reference.display()))?;
    if (a.width, a.height) != (b.width, b.height) {
        return Err(anyhow!(
            "sizes differ: {} is {}x{}, {} is {}x{}",
            args.image.display(),
            a.width,
            a.height,
            args.reference.display(),
            b.width,
            b.height
        ));
    }
    let m = metrics::compare(&a, &b, args.exposure, args.tonemap.tonemap());
    println!(
        "RMSE {:.6} (relative {:.4}) | SSIM {:.4} | FLIP {:.4} | mean ratio {:.4} | reference mean {:.6}",
        m.rmse, m.relative_rmse, m.ssim, m.flip, m.mean_ratio, m.reference_mean
    );
    if let Some(p) = &args.json {
        std::fs::write(p, serde_json::to_string_pretty(&m)?)
            .map_err(|e| anyhow!("cannot write {}: {e}", p.display()))?;
    }
    Ok(())
}
