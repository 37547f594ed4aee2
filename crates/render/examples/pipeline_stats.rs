//! What the Vulkan driver makes of one of Strata's compute shaders: the
//! statistics it reports for the compiled pipeline through
//! `VK_KHR_pipeline_executable_properties` (on NVIDIA: registers a thread,
//! shared memory, spills), which decide how many warps an SM keeps resident
//! and so how much of a latency-bound walk's waiting is hidden (issue 36,
//! `bench/issue36-floors/`). wgpu does not expose them, so this opens its own
//! Vulkan device.
//!
//! ```text
//! cargo run --release -p strata-render --example pipeline_stats -- \
//!     ray_exact_deferred.wgsl cs_exact_march_hits EXACT_CAVE_SKIP=1,EXACT_BEAM_SEARCH=1
//! ```
//!
//! The shader is composed as the renderer composes it, its overrides set
//! from the third argument (`NAME=VALUE,...`; the rest keep their defaults),
//! translated to SPIR-V by naga with its default options (no bounds checks,
//! no loop bounding: close to what wgpu hands a driver with robust buffer
//! access), and compiled with every binding the entry point uses in a
//! descriptor set layout of its own.

use anyhow::{Context, anyhow, bail};
use ash::vk;
use std::collections::BTreeMap;
use std::ffi::CStr;

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [shader, entry, rest @ ..] = args.as_slice() else {
        bail!("usage: pipeline_stats SHADER.wgsl ENTRY [NAME=VALUE,...]");
    };
    let constants = rest.first().map(String::as_str).unwrap_or("");
    let words = spirv(shader, entry, constants)?;
    let sets = bindings(shader)?;
    // SAFETY: plain Vulkan calls on objects made here, destroyed before exit.
    unsafe { report(&words, entry, &sets) }
}

/// The entry point's SPIR-V with the overrides `NAME=VALUE,...` applied.
fn spirv(shader: &str, entry: &str, constants: &str) -> anyhow::Result<Vec<u32>> {
    let text = strata_render::shaders::compose(shader)?;
    let module = naga::front::wgsl::parse_str(&text).map_err(|e| anyhow!("{shader}: {e}"))?;
    let info = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::all(),
    )
    .validate(&module)
    .map_err(|e| anyhow!("{shader}: {e:?}"))?;
    let mut values = naga::back::PipelineConstants::default();
    for pair in constants.split(',').filter(|p| !p.is_empty()) {
        let (name, value) = pair
            .split_once('=')
            .with_context(|| format!("{pair}: not NAME=VALUE"))?;
        values.insert(name.to_string(), value.parse()?);
    }
    let stage = naga::ShaderStage::Compute;
    let (module, info) = naga::back::pipeline_constants::process_overrides(
        &module,
        &info,
        Some((stage, entry)),
        &values,
    )
    .map_err(|e| anyhow!("{e:?}"))?;
    let options = naga::back::spv::Options {
        lang_version: (1, 3),
        ..Default::default()
    };
    let pipeline = naga::back::spv::PipelineOptions {
        shader_stage: stage,
        entry_point: entry.to_string(),
    };
    naga::back::spv::write_vec(&module, &info, &options, Some(&pipeline))
        .map_err(|e| anyhow!("{e:?}"))
}

/// Each set's bindings and their descriptor types, from the module's
/// resource variables.
fn bindings(shader: &str) -> anyhow::Result<BTreeMap<u32, Vec<(u32, vk::DescriptorType)>>> {
    let text = strata_render::shaders::compose(shader)?;
    let module = naga::front::wgsl::parse_str(&text).map_err(|e| anyhow!("{shader}: {e}"))?;
    let mut sets: BTreeMap<u32, Vec<(u32, vk::DescriptorType)>> = BTreeMap::new();
    for (_, var) in module.global_variables.iter() {
        let Some(rb) = &var.binding else { continue };
        let ty = match var.space {
            naga::AddressSpace::Uniform => vk::DescriptorType::UNIFORM_BUFFER,
            naga::AddressSpace::Storage { .. } => vk::DescriptorType::STORAGE_BUFFER,
            _ => match module.types[var.ty].inner {
                naga::TypeInner::Image {
                    class: naga::ImageClass::Storage { .. },
                    ..
                } => vk::DescriptorType::STORAGE_IMAGE,
                naga::TypeInner::Image { .. } => vk::DescriptorType::SAMPLED_IMAGE,
                naga::TypeInner::Sampler { .. } => vk::DescriptorType::SAMPLER,
                ref other => bail!("binding {}: {other:?}", rb.binding),
            },
        };
        sets.entry(rb.group).or_default().push((rb.binding, ty));
    }
    Ok(sets)
}

unsafe fn report(
    words: &[u32],
    entry_name: &str,
    sets: &BTreeMap<u32, Vec<(u32, vk::DescriptorType)>>,
) -> anyhow::Result<()> {
    let entry = unsafe { ash::Entry::load()? };
    let app = vk::ApplicationInfo::default().api_version(vk::API_VERSION_1_3);
    let instance = unsafe {
        entry.create_instance(
            &vk::InstanceCreateInfo::default().application_info(&app),
            None,
        )?
    };
    let physical = unsafe { instance.enumerate_physical_devices()? };
    let chosen = physical
        .iter()
        .copied()
        .find(|&p| {
            let props = unsafe { instance.get_physical_device_properties(p) };
            props.device_type == vk::PhysicalDeviceType::DISCRETE_GPU
        })
        .or_else(|| physical.first().copied())
        .context("no Vulkan device")?;
    let props = unsafe { instance.get_physical_device_properties(chosen) };
    let name = unsafe { CStr::from_ptr(props.device_name.as_ptr()) };
    println!("device: {}", name.to_string_lossy());
    let family = unsafe { instance.get_physical_device_queue_family_properties(chosen) }
        .iter()
        .position(|f| f.queue_flags.contains(vk::QueueFlags::COMPUTE))
        .context("no compute queue")? as u32;
    let supported = unsafe { instance.enumerate_device_extension_properties(chosen)? };
    let wanted = ash::khr::pipeline_executable_properties::NAME;
    if !supported
        .iter()
        .any(|e| e.extension_name_as_c_str() == Ok(wanted))
    {
        bail!(
            "{} lacks {}: its driver reports no pipeline statistics",
            name.to_string_lossy(),
            wanted.to_string_lossy()
        );
    }
    let priorities = [1.0];
    let queues = [vk::DeviceQueueCreateInfo::default()
        .queue_family_index(family)
        .queue_priorities(&priorities)];
    let extensions = [ash::khr::pipeline_executable_properties::NAME.as_ptr()];
    let mut executable_info = vk::PhysicalDevicePipelineExecutablePropertiesFeaturesKHR::default()
        .pipeline_executable_info(true);
    let device = unsafe {
        instance.create_device(
            chosen,
            &vk::DeviceCreateInfo::default()
                .queue_create_infos(&queues)
                .enabled_extension_names(&extensions)
                .push_next(&mut executable_info),
            None,
        )?
    };
    let mut layouts = Vec::new();
    let top = sets.keys().max().copied().unwrap_or(0);
    for set in 0..=top {
        let entries: Vec<_> = sets
            .get(&set)
            .into_iter()
            .flatten()
            .map(|&(binding, ty)| {
                vk::DescriptorSetLayoutBinding::default()
                    .binding(binding)
                    .descriptor_type(ty)
                    .descriptor_count(1)
                    .stage_flags(vk::ShaderStageFlags::COMPUTE)
            })
            .collect();
        layouts.push(unsafe {
            device.create_descriptor_set_layout(
                &vk::DescriptorSetLayoutCreateInfo::default().bindings(&entries),
                None,
            )?
        });
    }
    let layout = unsafe {
        device.create_pipeline_layout(
            &vk::PipelineLayoutCreateInfo::default().set_layouts(&layouts),
            None,
        )?
    };
    let module = unsafe {
        device.create_shader_module(&vk::ShaderModuleCreateInfo::default().code(words), None)?
    };
    let entry_c = std::ffi::CString::new(entry_name)?;
    let stage = vk::PipelineShaderStageCreateInfo::default()
        .stage(vk::ShaderStageFlags::COMPUTE)
        .module(module)
        .name(&entry_c);
    let info = vk::ComputePipelineCreateInfo::default()
        .stage(stage)
        .layout(layout)
        .flags(vk::PipelineCreateFlags::CAPTURE_STATISTICS_KHR);
    let pipeline = unsafe {
        device
            .create_compute_pipelines(vk::PipelineCache::null(), &[info], None)
            .map_err(|(_, e)| e)?[0]
    };
    let ext = ash::khr::pipeline_executable_properties::Device::new(&instance, &device);
    let executables = unsafe {
        ext.get_pipeline_executable_properties(&vk::PipelineInfoKHR::default().pipeline(pipeline))?
    };
    for (index, exe) in executables.iter().enumerate() {
        let name = unsafe { CStr::from_ptr(exe.name.as_ptr()) };
        println!(
            "executable {index}: {} (subgroup {})",
            name.to_string_lossy(),
            exe.subgroup_size
        );
        let stats = unsafe {
            ext.get_pipeline_executable_statistics(
                &vk::PipelineExecutableInfoKHR::default()
                    .pipeline(pipeline)
                    .executable_index(index as u32),
            )?
        };
        for s in stats {
            let name = unsafe { CStr::from_ptr(s.name.as_ptr()) }.to_string_lossy();
            // SAFETY: the union member the format names.
            let value = unsafe {
                match s.format {
                    vk::PipelineExecutableStatisticFormatKHR::BOOL32 => format!("{}", s.value.b32),
                    vk::PipelineExecutableStatisticFormatKHR::INT64 => format!("{}", s.value.i64),
                    vk::PipelineExecutableStatisticFormatKHR::UINT64 => format!("{}", s.value.u64),
                    _ => format!("{}", s.value.f64),
                }
            };
            println!("  {name}: {value}");
        }
    }
    unsafe {
        device.destroy_pipeline(pipeline, None);
        device.destroy_shader_module(module, None);
        device.destroy_pipeline_layout(layout, None);
        for l in layouts {
            device.destroy_descriptor_set_layout(l, None);
        }
        device.destroy_device(None);
        instance.destroy_instance(None);
    }
    Ok(())
}
