rtl/bandpass_sos.v
rtl/correlator_bank.v
rtl/peak_detector.v
rtl/receiver_top.v
