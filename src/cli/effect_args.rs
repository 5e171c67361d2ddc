//! Command-line flags for the visual effects: isosurface, window, lighting, gradients, MIP
//! colouring and X-ray attenuation (shared by `render` and `bench`).

use clap::Args;
use leapview::settings::RenderSettings;
use leapview::settings::effects::{GradientScheme, IsoSettings, Light, MipColor, Phong, Shading};

use super::parse::{parse_vec3, parse_window};

/// Effect parameters; each flag left out keeps the renderer's default.
#[derive(Args, Debug, Clone, Default)]
pub struct EffectArgs {
    /// Isosurface value in data units, HU for CT (default: mid-range).
    #[arg(long, allow_hyphen_values = true, help_heading = "Mode settings")]
    pub iso: Option<f64>,
    /// Isosurface refinement steps (false position) between the two samples around a hit, 0 to 16
    /// (default 4).
    #[arg(long, help_heading = "Mode settings", hide_short_help = true)]
    pub iso_refine: Option<u32>,
    /// Window LO,HI mapped to black..white by MIP, MinIP and X-ray.
    ///
    /// Default: the header's, else the 0.1 to 99.9 percentile of the data.
    #[arg(long, value_parser = parse_window, allow_hyphen_values = true, help_heading = "Mode settings")]
    pub window: Option<[f64; 2]>,
    /// Lighting in DVR and isosurface modes (default: on).
    #[arg(long, value_enum, help_heading = "Lighting")]
    pub shading: Option<Shading>,
    /// Light: headlight (the default) or a direction X,Y,Z it shines along.
    #[arg(long, value_parser = parse_light, allow_hyphen_values = true, help_heading = "Lighting")]
    pub light: Option<Light>,
    /// Phong coefficients KA,KD,KS,N: ambient, diffuse, specular, and the specular exponent
    /// (default 0.3,0.7,0.25,24).
    #[arg(long, value_parser = parse_phong, help_heading = "Lighting", hide_short_help = true)]
    pub phong: Option<Phong>,
    /// Gradient estimator for lighting (default: central).
    #[arg(long, value_enum, help_heading = "Lighting", hide_short_help = true)]
    pub gradient: Option<GradientScheme>,
    /// Shadows in lit DVR: each lit sample shadowed by the opacity between it and the light
    /// (a directional light by a shadow ray that leaps empty space; the headlight by what lies
    /// in front of the sample) (default: off).
    #[arg(long, value_enum, help_heading = "Lighting", hide_short_help = true)]
    pub shadows: Option<Switch>,
    /// Distance between a shadow ray's samples in voxels, 1/8 to 4 (default 1).
    #[arg(long, help_heading = "Lighting", hide_short_help = true)]
    pub shadow_step: Option<f64>,
    /// How far a shadow ray reaches, as a share of the volume's diagonal in (0, 1] (default 1:
    /// all the way; less keeps shadows local).
    #[arg(long, help_heading = "Lighting", hide_short_help = true)]
    pub shadow_reach: Option<f64>,
    /// The light's angular radius in degrees, 0 to 20, for soft shadows (default 0: hard).
    /// Each pixel's shadow rays aim at their own point of the light, so render refines soft
    /// shadows over --refine frames (16 where not given).
    #[arg(long, help_heading = "Lighting", hide_short_help = true)]
    pub shadow_softness: Option<f64>,
    /// Ambient occlusion in lit DVR and isosurfaces: each lit sample's ambient light scaled by
    /// how open its surroundings are (six short rays over its open side) (default: off).
    #[arg(long, value_enum, help_heading = "Lighting", hide_short_help = true)]
    pub occlusion: Option<Switch>,
    /// How far the occlusion rays reach in voxels, 1 to 16 (default 4).
    #[arg(long, help_heading = "Lighting", hide_short_help = true)]
    pub occlusion_radius: Option<f64>,
    /// DVR: composite samples whose weight in the pixel, α·(1 − opacity in front), is below this
    /// unlit, skipping their gradients (default 0: light every sample).
    #[arg(long, help_heading = "Lighting", hide_short_help = true)]
    pub light_min_weight: Option<f64>,
    /// MIP and MinIP colour (default: window).
    #[arg(
        long,
        value_enum,
        help_heading = "Mode settings",
        hide_short_help = true
    )]
    pub mip_color: Option<MipColor>,
    /// X-ray attenuation per millimetre at the window's top, for the xray-attenuation mode (default
    /// 0.019, about water's at 70 keV).
    #[arg(long, help_heading = "Mode settings", hide_short_help = true)]
    pub xray_density: Option<f64>,
}

impl EffectArgs {
    /// Writes the given flags into `settings` (validation is the caller's).
    pub fn apply(&self, settings: &mut RenderSettings) {
        let iso = IsoSettings {
            value: self.iso.or(settings.iso.value),
            refine_iterations: self.iso_refine.unwrap_or(settings.iso.refine_iterations),
        };
        settings.iso = iso;
        settings.window = self.window.or(settings.window);
        settings.shading = self.shading.unwrap_or(settings.shading);
        settings.light = self.light.unwrap_or(settings.light);
        settings.phong = self.phong.unwrap_or(settings.phong);
        settings.gradient = self.gradient.unwrap_or(settings.gradient);
        settings.light_min_weight = self.light_min_weight.unwrap_or(settings.light_min_weight);
        if let Some(on) = self.shadows {
            settings.shadows.on = on == Switch::On;
        }
        settings.shadows.step_vox = self.shadow_step.unwrap_or(settings.shadows.step_vox);
        settings.shadows.reach = self.shadow_reach.unwrap_or(settings.shadows.reach);
        if let Some(on) = self.occlusion {
            settings.occlusion.on = on == Switch::On;
        }
        settings.occlusion.radius_vox = self
            .occlusion_radius
            .unwrap_or(settings.occlusion.radius_vox);
        settings.shadows.softness_deg = self
            .shadow_softness
            .unwrap_or(settings.shadows.softness_deg);
        settings.mip_color = self.mip_color.unwrap_or(settings.mip_color);
        settings.xray_density_per_mm = self.xray_density.unwrap_or(settings.xray_density_per_mm);
    }
}

/// A feature on or off.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Switch {
    /// On.
    On,
    /// Off.
    Off,
}

fn parse_light(s: &str) -> Result<Light, String> {
    if s.eq_ignore_ascii_case("headlight") {
        return Ok(Light::Headlight);
    }
    let d = parse_vec3(s)?;
    if d.iter().all(|c| *c == 0.0) {
        return Err("the light direction must not be zero".into());
    }
    Ok(Light::Direction(d))
}

fn parse_phong(s: &str) -> Result<Phong, String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    let values: Vec<f64> = parts
        .iter()
        .map(|p| p.parse::<f64>().ok().filter(|v| v.is_finite()))
        .collect::<Option<_>>()
        .ok_or_else(|| format!("{s:?} holds something that is not a finite number"))?;
    let [ambient, diffuse, specular, shininess] = values.as_slice() else {
        return Err(format!("expected KA,KD,KS,N (four numbers), got {s:?}"));
    };
    Ok(Phong {
        ambient: *ambient,
        diffuse: *diffuse,
        specular: *specular,
        shininess: *shininess,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn windows_lights_and_phong_parse_and_reject() {
        assert_eq!(parse_window("-100,300"), Ok([-100.0, 300.0]));
        assert!(parse_window("300,-100").is_err());
        assert!(parse_window("1").is_err());
        assert!(parse_window("0,inf").is_err());
        assert_eq!(parse_light("HeadLight"), Ok(Light::Headlight));
        assert_eq!(
            parse_light("0,-1,0"),
            Ok(Light::Direction([0.0, -1.0, 0.0]))
        );
        assert!(parse_light("0,0,0").is_err());
        let p = parse_phong("0.1,0.8,0.5,32").expect("four numbers parse");
        assert_eq!(
            (p.ambient, p.diffuse, p.specular, p.shininess),
            (0.1, 0.8, 0.5, 32.0)
        );
        assert!(parse_phong("0.1,0.8,0.5").is_err());
        assert!(parse_phong("0.1,0.8,nan,3").is_err());
    }

    #[test]
    fn flags_left_out_keep_the_defaults() {
        let mut settings = RenderSettings::default();
        EffectArgs::default().apply(&mut settings);
        assert_eq!(settings, RenderSettings::default());
        let args = EffectArgs {
            iso: Some(300.0),
            shading: Some(Shading::Off),
            ..EffectArgs::default()
        };
        args.apply(&mut settings);
        assert_eq!(settings.iso.value, Some(300.0));
        assert_eq!(settings.shading, Shading::Off);
        assert_eq!(
            settings.iso.refine_iterations,
            RenderSettings::default().iso.refine_iterations
        );
    }
}
