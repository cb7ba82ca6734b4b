# The devices: one folder each, drivers/<device>/ (docs/drivers.md, "Adding a device"). Adding a
# device is adding its folder's name here. This order is the registry's: `daq devices`, the
# docs and the messages that list the drivers follow it.
set(CALDAQ_DEVICES ids3010 ptu300 line_gauge temper halsampler shdr)
